"""Plots of a simulated harvest: the gripper's path and the arm and gripper at each grasp
among the berries and canes, and the position and orientation errors against time per
berry. Each berry has one colour in every panel and is named as on the console: by its
tag in the tag world, by its number in the bush map (the C1 picture's) in the rendered
bush. Filled: harvested; hollow: not; a green diamond: unripe; the dotted lines are the
tolerances a grasp must meet."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.harvest.records.report import HarvestReport
from softarm.harvest.rigs.sim.rig import SimRig
from softarm.viz.arm import arm_line, clip_to_box
from softarm.viz.gripper import gripper_polylines

__all__ = ["berry_colours", "berry_paths", "plot_errors", "plot_run", "plot_scene", "run_ids"]

#: The colour of what is drawn for an unripe berry, and of a berry the run never named.
UNRIPE, UNNAMED = "yellowgreen", "0.45"


def berry_colours(tags: list[int]) -> dict[int, str]:
    """One matplotlib colour per berry id (a tag, or a bush-map number), in the run's
    order (the same in every panel)."""
    return {tag: f"C{k % 10}" for k, tag in enumerate(tags)}


def run_ids(rig: SimRig, report: HarvestReport) -> dict[int, int]:
    """Each true berry's id as the run named it (the log, the report, the console): its
    tag in the tag world; in the rendered bush, the number of the bush-map entry that
    stood for it (a berry the map never placed is left out)."""
    if rig.scene is None:
        return {b.tag_id: b.tag_id for b in rig.bush.berries}
    ids: dict[int, int] = {}
    for result in report.berries:
        true = rig.scene.truth_of(result.tag_id)
        if true is not None:
            ids.setdefault(true.tag_id, result.tag_id)
    return ids


def _tolerance(rig: SimRig) -> tuple[float, float]:
    """The grasp tolerance of the rig's ``[harvest]``: position (mm), pointing (deg)."""
    config = rig.machine.config
    return 1e3 * config.fine_tolerance, config.angle_tolerance_deg


def plot_run(rig: SimRig, report: HarvestReport, path: str | Path) -> None:
    """The scene (whole, and zoomed on the berries) and the errors in one image."""
    import matplotlib.pyplot as plt

    colours = berry_colours([b.tag_id for b in report.berries])
    fig = plt.figure(figsize=(19, 6.8))
    grid = fig.add_gridspec(2, 3, width_ratios=(1.0, 1.0, 1.25))
    scene = fig.add_subplot(grid[:, 0], projection="3d")
    plot_scene(scene, rig, report, colours)
    ax_z = fig.add_subplot(grid[:, 1], projection="3d")
    plot_scene(ax_z, rig, report, colours, zoom=True)
    ax_p = fig.add_subplot(grid[0, 2])
    ax_o = fig.add_subplot(grid[1, 2], sharex=ax_p)
    plot_errors(ax_p, ax_o, rig.machine.log.records, colours, _tolerance(rig), _named(rig, report))
    fig.legend(*scene.get_legend_handles_labels(), loc="lower left", ncol=4, fontsize=7,
               frameon=False)  # fmt: skip
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    Path(path).parent.mkdir(parents=True, exist_ok=True)  # outputs create their folders
    fig.savefig(path, dpi=110)
    plt.close(fig)


def berry_paths(
    trajectory: list[FloatArray], period: float, records: list[dict[str, Any]]
) -> tuple[dict[int, list[FloatArray]], list[FloatArray]]:
    """The true gripper path cut into each berry's approach (from the start of initial
    placement to the grasp: a list of pieces per tag, a berry may be tried twice) and the
    rest (ramps to and from the ready pose).

    ``trajectory`` holds one position after every clock step of ``period`` seconds (the
    rig's :class:`~softarm.harvest.rigs.sim.devices.ArmWatch`); the stages' times come from the
    run log's transitions."""
    path = np.asarray(trajectory, dtype=np.float64).reshape(-1, 3)
    times = period * np.arange(1, len(path) + 1)
    windows: list[tuple[int, float, float]] = []
    start: tuple[int, float] | None = None
    for r in records:
        if r["kind"] != "transition":
            continue
        if r["new"] == "initial_placement":
            start = (r["berry"], r["t"])
        elif start is not None and r["new"] in ("grasp", "return_home", "done", "fault"):
            windows.append((start[0], start[1], r["t"]))
            start = None
    approach: dict[int, list[FloatArray]] = {}
    inside = np.zeros(len(path), dtype=bool)
    for tag, t0, t1 in windows:
        sel = (times >= t0 - 1e-9) & (times <= t1 + 1e-9)
        if sel.any():
            approach.setdefault(tag, []).append(path[sel])
            inside |= sel
    rest = [path[idx] for idx in _runs(~inside)]
    return approach, rest


def _runs(mask: npt.NDArray[np.bool_]) -> list[npt.NDArray[np.intp]]:
    """Index runs where ``mask`` is True, each grown by one on both sides so that the
    pieces of a cut line still meet."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) > 1)
    out = []
    for part in np.split(idx, breaks + 1):
        lo, hi = max(part[0] - 1, 0), min(part[-1] + 1, mask.size - 1)
        out.append(np.arange(lo, hi + 1))
    return out


def plot_scene(
    ax: Any,
    rig: SimRig,
    report: HarvestReport,
    colours: dict[int, str] | None = None,
    zoom: bool = False,
) -> None:
    """3D: canes, berries (filled: harvested, hollow: not, labelled by tag), the true
    gripper path per berry (thin, the berry's colour; ramps to the ready pose grey), and
    the true arm with its gripper at every grasp. ``zoom``: only the box around the
    berries and the approaches (everything clipped to it), without the legend."""
    tags = [b.tag_id for b in rig.bush.berries]
    colours = colours or berry_colours(tags)
    offset = rig.machine.config.grasp_offset
    records = rig.machine.log.records
    period = rig.machine.config.period
    traj = rig.watch.trajectory
    berries = np.array([b.position for b in rig.bush.berries]).reshape(-1, 3)
    # The path is cut by time; only when every step lasted one period (as the servo
    # sleeps) do the positions' times follow from their count.
    approach: dict[int, list[FloatArray]] = {}
    rest: list[FloatArray] = []
    if traj and abs(len(traj) * period - rig.clock.now()) <= period / 2:
        approach, rest = berry_paths(traj, period, records)
    elif traj:
        rest = [np.asarray(traj)]
    if zoom:
        # The last centimetres of each approach and the gripper around its berry.
        lo, hi = _cube(berries.min(0) - 0.05, berries.max(0) + 0.05)
    else:
        lo, hi = _cube(np.vstack([berries, np.asarray(traj).reshape(-1, 3), np.zeros((1, 3))]))

    def line(pts: Any, **style: Any) -> None:
        ax.plot(*clip_to_box(pts, lo, hi).T, **style)

    for i, branch in enumerate(rig.bush.branches):
        line(branch.points(120), color="saddlebrown", lw=2, alpha=0.8,
             label="canes" if i == 0 else None)  # fmt: skip
    for k, piece in enumerate(rest):
        line(piece, color="0.55", lw=0.6, alpha=0.7,
             label="gripper path to/from the ready pose" if k == 0 else None)  # fmt: skip
    for n, (tag, pieces) in enumerate(approach.items()):
        for piece in pieces:
            line(piece, color=colours.get(tag, "k"), lw=0.9,
                 label="gripper path, approach (berry's colour)" if n == 0 else None)  # fmt: skip
    # The plant's shape is kept at every grasp (SimGripper.grasp_errors), right after fine
    # positioning ends: the berry of each is the one whose fine positioning ended.
    grasped = [r["berry"] for r in records if r["kind"] == "transition"
               and r["old"] == "fine_positioning" and r["new"] in ("grasp", "done")]  # fmt: skip
    arm = rig.plant.arm
    for k, q in enumerate(rig.gripper.grasp_shapes):
        colour = colours.get(grasped[k], "k") if k < len(grasped) else "k"
        line(arm_line(arm, q, 40), color="0.35", lw=2.5, alpha=0.45,
             label="arm at grasp" if k == 0 else None)  # fmt: skip
        for j, part in enumerate(gripper_polylines(np.asarray(arm.forward(q)), offset)):
            line(part, color=colour, lw=2.5 if zoom else 1.5,
                 label="gripper at grasp" if k == 0 and j == 0 else None)  # fmt: skip
    ids, picked = run_ids(rig, report), set(rig.gripper.delivered)
    prefix = "" if rig.scene is None else "#"
    for b in rig.bush.berries:
        _berry(ax, b, ids.get(b.tag_id), colours, b.tag_id in picked, prefix, zoom, hi[2] - lo[2])
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]))
    ax.set(xlabel="x (m)", ylabel="y (m)")
    ax.set_zlabel("z (m)")
    ax.set_box_aspect((1, 1, 1))
    named = "tag" if rig.scene is None else "bush-map number, as on the console"
    if zoom:
        ax.set_title("around the berries (colours as in the errors)")
        return
    _legend(ax, named, rig.scene is not None)
    unripe = sum(b.ripeness < 0.5 and b.tag_id not in picked for b in rig.bush.berries)
    left = f", {unripe} unripe left" if unripe else ""
    ax.set_title(f"seed {rig.bush.seed}: {report.harvested}/{report.attempted} harvested{left}")


def _berry(
    ax: Any, b: Any, run_id: int | None, colours: dict[int, str], picked: bool,
    prefix: str, zoom: bool, height: float,
) -> None:  # fmt: skip
    """One true berry: a circle in its run colour (filled once picked), a green diamond
    if unripe, grey if the run never named it; its run name above."""
    unripe = b.ripeness < 0.5
    c = UNRIPE if unripe else colours.get(run_id, UNNAMED) if run_id is not None else UNNAMED
    ax.scatter(*b.position, s=45 if zoom else 50, depthshade=False, alpha=0.9, edgecolor=c,
               linewidth=1.5, facecolor=c if picked else "none",
               marker="D" if unripe else "o")  # fmt: skip
    text = "?" if run_id is None else f"{prefix}{run_id}"
    if unripe:
        text = "unripe" if run_id is None else f"{text} unripe"
    ax.text(*np.add(b.position, (0.0, 0.0, 0.06 * height)), text, color=c,
            fontsize=9 if zoom else 8, ha="center", weight="bold")  # fmt: skip


def _legend(ax: Any, named: str, bush: bool) -> None:
    """The berries' markers, for the scene's legend (the lines are labelled as drawn)."""
    ax.scatter([], [], s=40, color="0.3", label=f"berry harvested (filled; its {named})")
    ax.scatter([], [], s=40, facecolor="none", edgecolor="0.3", label="berry not harvested")
    ax.scatter([], [], s=40, marker="D", facecolor="none", edgecolor=UNRIPE, label="unripe berry")
    if bush:
        ax.scatter([], [], s=40, facecolor="none", edgecolor=UNNAMED,
                   label="ripe berry the map never placed (?)")  # fmt: skip
    # Drawn by plot_run under the figure, not over the box.


def _named(rig: SimRig, report: HarvestReport) -> dict[int, str]:
    """Each berry of the run (by its id in the log) as the errors' legend names it: as
    on the console, flagged when harvested outside tolerance."""
    pos_mm, ang_deg = _tolerance(rig)
    names = {}
    for r in report.berries:
        name = f"tag {r.tag_id}" if rig.scene is None else f"#{r.tag_id}"
        pos, ang = r.true_position_error_mm, r.true_orientation_error_deg
        off = (pos is not None and pos > pos_mm) or (ang is not None and ang > ang_deg)
        names[r.tag_id] = f"{name} OUTSIDE TOLERANCE" if r.harvested and off else name
    return names


def _cube(lo: Any, hi: Any | None = None) -> tuple[FloatArray, FloatArray]:
    """The cube (equal axes) around the box lo..hi, or around the points ``lo``."""
    if hi is None:
        pts = np.asarray(lo)
        lo, hi = pts.min(0), pts.max(0)
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    centre, half = (lo + hi) / 2, 0.55 * float((hi - lo).max())
    return centre - half, centre + half


def plot_errors(
    ax_p: Any,
    ax_o: Any,
    records: list[dict[str, Any]],
    colours: dict[int, str] | None = None,
    tolerance: tuple[float, float] | None = None,
    names: dict[int, str] | None = None,
) -> None:
    """Position error (mm, log scale) and pointing error (deg) against time from each
    berry's start, in placement and fine positioning (as the cameras measured them);
    ``tolerance`` (mm, deg) drawn as dotted lines, ``names``: each berry's legend."""
    berries: dict[int, list[dict[str, Any]]] = {}
    for r in records:
        if r["kind"] == "step" and r["position_error_m"] is not None:
            if r["state"] in ("initial_placement", "fine_positioning"):
                berries.setdefault(r["berry"], []).append(r)
    colours = colours or berry_colours(list(berries))
    for tag, steps in berries.items():
        t0, colour = steps[0]["t"], colours.get(tag, "k")
        for stage, style in (("initial_placement", "--"), ("fine_positioning", "-")):
            part = [s for s in steps if s["state"] == stage]
            t = [s["t"] - t0 for s in part]
            name = (names or {}).get(tag, f"tag {tag}")
            label = name if stage == "fine_positioning" else None
            ax_p.semilogy(
                t,
                [1e3 * s["position_error_m"] for s in part],
                style,
                color=colour,
                lw=1,
                label=label,
            )
            ax_o.plot(
                t, [np.degrees(s["orientation_error_rad"]) for s in part], style, color=colour
            )
    if tolerance is not None:
        ax_p.axhline(tolerance[0], color="k", ls=":", lw=0.9,
                     label=f"tolerance {tolerance[0]:g} mm")  # fmt: skip
        ax_o.axhline(tolerance[1], color="k", ls=":", lw=0.9)
        ax_o.text(0.99, tolerance[1], f"tolerance {tolerance[1]:g} deg", ha="right",
                  va="bottom", fontsize=7, transform=ax_o.get_yaxis_transform())  # fmt: skip
    ax_p.set(
        ylabel="position error (mm, measured)",
        title="closed loop: placement (dashed, to the pre-grasp point), fine positioning (solid)",
    )
    ax_o.set(
        xlabel="time from the first closed-loop step (s)", ylabel="pointing error (deg, measured)"
    )
    if berries:
        ax_p.legend(fontsize=7, ncol=2)
