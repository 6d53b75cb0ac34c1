"""The pictures tell the run as the console does (issue 39, items 3 and 4): each berry in
its own colour and named as on the console (its tag, or its bush-map number), harvested
filled, unripe marked, the tolerances drawn, a grasp outside them flagged; the C1 picture
titled, with a legend and the truth under the map; a dry run's summary says whose errors
it gives."""

from __future__ import annotations

import os
from types import SimpleNamespace
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from render_required import rendering
from softarm.commands.harvest import line, summary
from softarm.harvest.records.c1_picture import _brighten, _framed
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.plots import _named, plot_run, run_ids
from softarm.harvest.rigs.sim.rig import build_sim_rig
from softarm.harvest_config import HarvestConfig

os.environ.setdefault("MUJOCO_GL", "egl")

#: A bush from the seeds reserved for CI (docs/architecture.md, "Seeds"), not picked.
SEED = 90012


def _fake_rig(truth: dict[int, int], scene: bool = True) -> Any:
    """A rig whose bush map entry ``k`` stands for the true berry ``truth[k]``."""
    berries = [SimpleNamespace(tag_id=t, ripeness=1.0) for t in (10, 11, 12)]
    found = {k: next(b for b in berries if b.tag_id == t) for k, t in truth.items()}
    return SimpleNamespace(
        scene=SimpleNamespace(truth_of=found.get) if scene else None,
        bush=SimpleNamespace(berries=berries),
        machine=SimpleNamespace(config=HarvestConfig()),
    )


def test_true_berries_are_named_as_the_run_named_them() -> None:
    report = HarvestReport([BerryResult(0), BerryResult(1), BerryResult(2)])
    rig = _fake_rig({0: 12, 2: 10})  # entry 1 stood for nothing (a phantom)
    assert run_ids(rig, report) == {12: 0, 10: 2}
    assert run_ids(_fake_rig({}, scene=False), report) == {10: 10, 11: 11, 12: 12}


def test_the_errors_legend_flags_a_grasp_outside_tolerance() -> None:
    off = BerryResult(1, harvested=True, true_position_error_mm=0.9)
    fine = BerryResult(2, harvested=True, true_position_error_mm=0.1)
    names = _named(_fake_rig({}), HarvestReport([off, fine]))
    assert names == {1: "#1 OUTSIDE TOLERANCE", 2: "#2"}


@pytest.mark.slow
def test_the_harvest_figure_fills_marks_and_draws_tolerances(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    rig = build_sim_rig(SimRigOptions(n_berries=3, seed=0, unripe_fraction=0.3))
    report = rig.run()
    kept: list[Any] = []
    monkeypatch.setattr(plt, "close", kept.append)
    plot_run(rig, report, tmp_path / "h.png")
    (fig,) = kept
    scene, ax_p, ax_o = fig.axes[0], fig.axes[2], fig.axes[3]
    picked = set(rig.gripper.delivered)
    assert picked
    for b, dots in zip(rig.bush.berries, scene.collections, strict=False):
        face = dots.get_facecolor()  # empty for facecolor "none"
        filled = len(face) > 0 and face[0][3] > 0
        assert filled == (b.tag_id in picked)
        assert dots.get_paths() and (b.ripeness < 0.5) == ("unripe" in _text_of(scene, b.tag_id))
    labels = ax_p.get_legend_handles_labels()[1]
    assert "tolerance 0.5 mm" in labels and f"tag {report.berries[0].tag_id}" in labels
    assert any("tolerance 5 deg" in t.get_text() for t in ax_o.texts)
    # Each berry's trace in its own colour, not all black.
    colours = {tuple(ln.get_color()) if not isinstance(ln.get_color(), str) else ln.get_color()
               for ln in ax_p.get_lines() if ln.get_linestyle() == "-"}  # fmt: skip
    assert len(colours) >= 2
    assert fig.legends  # the scene's legend is under the figure, not over the box
    plt.close(fig)


def _text_of(ax: Any, tag: int) -> str:
    return next(t.get_text() for t in ax.texts if t.get_text().split()[0].lstrip("#") == str(tag))


def test_the_c1_picture_has_a_title_band_and_a_legend() -> None:
    dim = np.full((60, 400, 3), 20, np.uint8)
    assert _brighten(dim).mean() > 60  # the dusk render lifted for the eye
    day = np.full((60, 400, 3), 150, np.uint8)
    assert np.array_equal(_brighten(day), day)  # a daylight one left as it is
    framed = _framed(dim, "What C1 saw")
    assert framed.shape[0] > dim.shape[0] + 40 and framed.shape[1] == 400
    assert framed[:34].max() > 200  # the title's white text
    assert framed[dim.shape[0] + 34 :].max() > 200  # the legend's


def test_the_bush_figure_names_berries_by_their_map_number(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    from softarm.harvest.records.c1_picture import c1_picture

    with rendering():
        rig = build_sim_rig(SimRigOptions(n_berries=4, seed=SEED, world="bush", survey=False))
    assert rig.scene is not None
    entries = [e.id for e in rig.scene.bush_map.berries]
    report = HarvestReport([BerryResult(k) for k in entries])
    ids = run_ids(rig, report)
    assert ids and set(ids.values()) <= set(entries)
    kept: list[Any] = []
    monkeypatch.setattr(plt, "close", kept.append)
    plot_run(rig, report, tmp_path / "h.png")
    texts = {t.get_text().split()[0] for t in kept[0].axes[0].texts}
    assert {f"#{k}" for k in ids.values()} <= texts
    assert not any(t.isdigit() and int(t) >= 10 for t in texts)  # not the world's tags
    picture = c1_picture(rig.scene, SEED)
    raw = rig.scene.c1_whole(0.0)
    assert picture.shape[0] > raw.shape[0] and picture.shape[1] == raw.shape[1]
    plt.close(kept[0])


def test_a_dry_run_says_its_errors_are_measured_and_prints_each_berry() -> None:
    measured = BerryResult(0, harvested=True, position_error_mm=0.2, duration_s=3.0)
    text = summary(HarvestReport([measured]).to_dict())
    assert "0.20 mm" in text and "as the cameras measured it" in text
    true = BerryResult(0, harvested=True, position_error_mm=0.2, true_position_error_mm=0.36)
    assert "(true, from the simulation)" in summary(HarvestReport([true]).to_dict())
    one = line(0, 1, measured, None, tagged=False)
    assert one.startswith("berry 1/1 (map #0): harvested") and "wall" not in one
