"""Plots of a simulated harvest: the gripper's path and the arm at each grasp among the
berries and canes, and the position and orientation errors against time per berry."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from softarm.harvest.report import HarvestReport
from softarm.harvest.sim_rig import SimRig

__all__ = ["plot_errors", "plot_run", "plot_scene"]


def plot_run(rig: SimRig, report: HarvestReport, path: str | Path) -> None:
    """Both figures side by side in one image at ``path``."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(15, 6.5))
    plot_scene(fig.add_subplot(1, 2, 1, projection="3d"), rig, report)
    ax_p = fig.add_subplot(2, 2, 2)
    ax_o = fig.add_subplot(2, 2, 4, sharex=ax_p)
    plot_errors(ax_p, ax_o, rig.machine.log.records)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_scene(ax: Any, rig: SimRig, report: HarvestReport) -> None:
    """3D: canes, berries (green harvested, red not), the true gripper path and the arm
    at every grasp."""
    for branch in rig.bush.branches:
        p = branch.points(60)
        ax.plot(p[:, 0], p[:, 1], p[:, 2], color="saddlebrown", lw=2)
    done = {b.tag_id for b in report.berries if b.harvested}
    for b in rig.bush.berries:
        ax.scatter(*b.position, color="green" if b.tag_id in done else "red", s=40)
    path = np.array(rig.watch.trajectory)
    if len(path):
        ax.plot(path[:, 0], path[:, 1], path[:, 2], color="tab:blue", lw=0.8, label="gripper")
    for q in rig.gripper.grasp_shapes:
        bb = rig.plant.arm.backbone(q, 20)
        ax.plot(bb[:, 0], bb[:, 1], bb[:, 2], color="0.4", lw=3, alpha=0.6)
    pts = np.concatenate([path, [[0, 0, 0]], [b.position for b in rig.bush.berries]])
    centre, half = pts.mean(0), 0.5 * np.ptp(pts, 0).max()
    ax.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half))
    ax.set(zlim=(centre[2] - half, centre[2] + half), xlabel="x (m)", ylabel="y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(f"seed {rig.bush.seed}: {len(done)}/{len(report.berries)} harvested")


def plot_errors(ax_p: Any, ax_o: Any, records: list[dict[str, Any]]) -> None:
    """Position error (mm, log scale) and pointing error (deg) against time from each
    berry's start, in placement and fine positioning (as the cameras measured them)."""
    berries: dict[int, list[dict[str, Any]]] = {}
    for r in records:
        if r["kind"] == "step" and r["position_error"] is not None:
            if r["state"] in ("initial_placement", "fine_positioning"):
                berries.setdefault(r["berry"], []).append(r)
    for k, (tag, steps) in enumerate(berries.items()):
        t0, colour = steps[0]["t"], f"C{k % 10}"
        for stage, style in (("initial_placement", "--"), ("fine_positioning", "-")):
            part = [s for s in steps if s["state"] == stage]
            t = [s["t"] - t0 for s in part]
            label = f"tag {tag}" if stage == "fine_positioning" else None
            ax_p.semilogy(
                t, [1e3 * s["position_error"] for s in part], style, color=colour, lw=1, label=label
            )
            ax_o.plot(t, [np.degrees(s["orientation_error"]) for s in part], style, color=colour)
    ax_p.axhline(1.0, color="k", ls=":", lw=0.8)
    ax_p.set(
        ylabel="position error (mm)",
        title="closed loop: placement (dashed, to the pre-grasp point), fine positioning (solid)",
    )
    ax_o.set(xlabel="time from the first closed-loop step (s)", ylabel="pointing error (deg)")
    if berries:
        ax_p.legend(fontsize=7, ncol=2)
