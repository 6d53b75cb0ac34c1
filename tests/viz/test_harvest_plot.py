"""The harvest figure: gripper drawn, berries labelled by tag, paths cut per berry, lines
inside the axes, legends."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.plots import berry_paths, plot_run
from softarm.harvest.rigs.sim.rig import build_sim_rig


def _transition(t, berry, old, new):
    return {"kind": "transition", "t": t, "berry": berry, "old": old, "new": new}


def test_paths_are_cut_into_each_berrys_approach() -> None:
    traj = [np.array([0.1 * i, 0.0, 0.0]) for i in range(10)]  # at t = 0.05, 0.10, ...
    records = [
        _transition(0.0, 10, "idle", "idle"),
        _transition(0.1, 10, "idle", "initial_placement"),
        _transition(0.2, 10, "initial_placement", "fine_positioning"),
        _transition(0.25, 10, "fine_positioning", "grasp"),
        _transition(0.35, 11, "idle", "initial_placement"),
        {"kind": "step", "t": 0.4},
        _transition(0.45, 11, "initial_placement", "fault"),
    ]
    approach, rest = berry_paths(traj, 0.05, records)
    assert sorted(approach) == [10, 11]
    (a10,) = approach[10]
    (a11,) = approach[11]
    assert np.allclose(a10[:, 0], [0.1, 0.2, 0.3, 0.4])  # t = 0.10 .. 0.25
    assert np.allclose(a11[:, 0], [0.6, 0.7, 0.8])  # t = 0.35 .. 0.45
    # The rest joins the approaches (one point of overlap each side).
    assert [list(np.round(p[:, 0], 6)) for p in rest] == [
        [0.0, 0.1],
        [0.4, 0.5, 0.6],
        [0.8, 0.9],
    ]


@pytest.mark.slow
def test_harvest_figure_draws_the_gripper_and_labels_berries(tmp_path, monkeypatch) -> None:
    rig = build_sim_rig(SimRigOptions(n_berries=2, seed=0))
    report = rig.run()
    kept = []
    monkeypatch.setattr(plt, "close", kept.append)
    plot_run(rig, report, tmp_path / "h.png")
    (fig,) = kept
    scene, zoom = fig.axes[0], fig.axes[1]
    labels = scene.get_legend_handles_labels()[1]
    for want in ("canes", "gripper at grasp", "arm at grasp", "berry harvested (filled; its tag)"):
        assert want in labels
    tags = {str(b.tag_id) for b in rig.bush.berries}
    for ax in (scene, zoom):
        assert {t.get_text() for t in ax.texts} == tags
        limits = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
        for line in ax.get_lines():
            pts = np.column_stack(line.get_data_3d())
            pts = pts[np.all(np.isfinite(pts), axis=1)]
            assert np.all(pts >= limits[:, 0] - 1e-9) and np.all(pts <= limits[:, 1] + 1e-9)
    # One gripper (three strokes) per grasp, in its berry's colour.
    grasps = len(rig.gripper.grasp_shapes)
    assert grasps >= 1
    strokes = [ln for ln in scene.get_lines() if ln.get_linewidth() == 1.5]
    assert len(strokes) == 3 * grasps
    plt.close(fig)
