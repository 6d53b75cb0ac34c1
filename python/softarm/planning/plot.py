"""Snapshots of a planned motion, like the planning paper's figures 3-5, and the point-set
baselines that collide, so that the comparison of tables 2-4 can be seen.

Every panel shares one cubic box around the arm's motion and the goal; the obstacle
curves are clipped to it (matplotlib's 3-D axes do not clip, and the curve scenario's
parabola climbs to z = 20 m), so every line stays inside the axes.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from softarm import _core
from softarm.checks import FloatArray
from softarm.planning.scenarios import COLLISION_DISTANCE, SUBSTEPS, Result, Scenario
from softarm.viz.arm import clip_to_box

__all__ = ["first_contact", "plot_plan", "snapshot_iterations"]


#: Backbone samples per section.
SAMPLES = 30
#: Colours of the arm's sections (proximal to distal) and of the baselines' arms.
SECTION_COLOURS = ("C0", "C1", "C2")
BASELINE_COLOURS = ("tab:red", "tab:purple", "tab:pink", "tab:olive", "tab:cyan")


def snapshot_iterations(plan: _core.Plan, count: int = 3) -> list[int]:
    """Iterations to draw: the first, evenly spaced ones, and the last."""
    last = plan.iterations
    return sorted({round(float(v)) for v in np.linspace(0, last, count)})


def first_contact(
    scenario: Scenario, plan: _core.Plan
) -> tuple[float, FloatArray, FloatArray] | None:
    """Where a path first comes closer than :data:`COLLISION_DISTANCE` to a true curve,
    judged as :func:`~softarm.planning.scenarios.run_method` judges it (every step and
    :data:`SUBSTEPS` configurations between steps): ``(iteration, q, contact point)``
    with a fractional iteration between steps, or None for a collision-free path."""
    chain, path = scenario.chain, np.asarray(plan.path)
    for i in range(len(path)):
        fractions = [0.0] if i == 0 else np.arange(1, SUBSTEPS + 1) / SUBSTEPS
        for f in fractions:
            q = path[i] if i == 0 else path[i - 1] + f * (path[i] - path[i - 1])
            near = min((_core.closest(chain, q, c) for c in scenario.curves),
                       key=lambda c: c.distance)  # fmt: skip
            if near.distance < COLLISION_DISTANCE:
                return i - 1 + f if i else 0.0, q, np.asarray(near.obstacle_point)
    return None


def plot_plan(
    scenario: Scenario,
    plan: _core.Plan,
    out: str | Path,
    title: str = "",
    baselines: Sequence[Result] = (),
) -> Path:
    """Draws the curves, the goal and the arm at a few iterations, one panel each; with
    ``baselines`` (the point-set results of :func:`~softarm.planning.scenarios.compare`),
    a last panel shows each one that collides at its first contact."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    chain = scenario.chain
    iters = snapshot_iterations(plan)
    colliding = [(r, c) for r in baselines if (c := first_contact(scenario, r.plan)) is not None]
    box = _box(chain, [plan.path[it] for it in iters]
               + [q for r in baselines for q in r.plan.path[:: max(1, len(r.plan.path) // 5)]]
               + [c[1] for _, c in colliding], scenario.goal)  # fmt: skip
    panels = len(iters) + (1 if colliding else 0)
    fig = plt.figure(figsize=(4.2 * panels, 4.9))
    for k, it in enumerate(iters):
        ax = fig.add_subplot(1, panels, k + 1, projection="3d")
        _scene(ax, scenario, box)
        _arm(ax, chain, plan.path[it], colours=SECTION_COLOURS, labels=True)
        tips = plan.tip_path[: it + 1]
        ax.plot(*_clip(tips, box).T, ":", color="0.35", lw=1, label="tip path")
        label = "final iteration" if it == plan.iterations else f"{it} iterations"
        ax.set_title(f"({chr(97 + k)}) proposed: {label}", fontsize=10)
    if colliding:
        ax = fig.add_subplot(1, panels, panels, projection="3d")
        _scene(ax, scenario, box, labels=False)
        for j, (r, (at, q, point)) in enumerate(colliding):
            colour = BASELINE_COLOURS[j % len(BASELINE_COLOURS)]
            ls = ("-", "--", "-.", ":")[j % 4]
            _arm(ax, chain, q, colours=(colour,) * chain.n_sections, ls=ls, lw=2,
                 label=f"{r.method}: contact at iteration {at:.1f}")  # fmt: skip
            ax.scatter(*point, marker="x", s=60, color="k", depthshade=False)
        ax.scatter([], [], marker="x", color="k", label="contact (< 1 cm)")
        ax.set_title(f"({chr(97 + len(iters))}) point models that collide", fontsize=10)
        ax.legend(loc="upper left", fontsize=7, framealpha=0.85)
    handles, labels = fig.axes[0].get_legend_handles_labels()
    # Under the proposed method's panels; the baselines' panel has its own legend.
    centre = 0.5 * len(iters) / panels
    fig.legend(handles, labels, loc="lower center", bbox_to_anchor=(centre, 0.0),
               ncol=len(labels), fontsize=8, frameon=False)  # fmt: skip
    if baselines and not colliding:
        title = f"{title}{' ' if title else ''}(no point model collides)"
    if title:
        fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)  # outputs create their folders
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def _box(chain: Any, configs: Sequence[Any], goal: FloatArray) -> tuple[FloatArray, FloatArray]:
    """A cube (lo, hi) around the arm in ``configs`` and the goal, 0.2 m of margin, its
    floor at the base when the arm stays above it."""
    pts = np.vstack([np.asarray(chain.backbone(q, SAMPLES)) for q in configs] + [goal[None]])
    lo, hi = pts.min(0) - 0.2, pts.max(0) + 0.2
    centre, half = (lo + hi) / 2, float((hi - lo).max()) / 2
    lo, hi = centre - half, centre + half
    if pts[:, 2].min() >= 0.0 and lo[2] < 0.0:  # the ground: shift the cube up onto it
        hi[2], lo[2] = hi[2] - lo[2], 0.0
    return lo, hi


def _clip(points: Any, box: tuple[FloatArray, FloatArray]) -> FloatArray:
    """``points`` (n, 3) with those outside ``box`` set to NaN (a break in the line)."""
    return clip_to_box(points, *box)


def _scene(
    ax: Any, scenario: Scenario, box: tuple[FloatArray, FloatArray], labels: bool = True
) -> None:
    """The obstacle curves (clipped to ``box``), the goal and the axes."""
    us = np.linspace(0.0, 1.0, 600)
    for i, curve in enumerate(scenario.curves):
        u0, u1 = curve.u_range
        pts = _clip(curve(u0 + (u1 - u0) * us), box)
        ax.plot(
            *pts.T, color="tab:brown", lw=2, label="obstacle curve" if i == 0 and labels else None
        )
    g = scenario.goal
    ax.scatter([g[0]], [g[1]], [g[2]], marker="*", s=140, color="gold", edgecolor="k",
               depthshade=False, label="goal" if labels else None, zorder=5)  # fmt: skip
    lo, hi = box
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]))
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (m)", fontsize=8)
    ax.set_ylabel("y (m)", fontsize=8)
    ax.set_zlabel("z (m)", fontsize=8)
    ax.tick_params(labelsize=7)


def _arm(
    ax: Any,
    chain: Any,
    q: Any,
    colours: Sequence[str],
    labels: bool = False,
    label: str | None = None,
    ls: str = "-",
    lw: float = 3,
) -> None:
    """The backbone at ``q``, one colour per section."""
    bb = np.asarray(chain.backbone(q, SAMPLES))
    for sec in range(chain.n_sections):
        part = bb[SAMPLES * sec : SAMPLES * (sec + 1)]
        name = f"segment {sec + 1}" if labels else (label if sec == 0 else None)
        ax.plot(*part.T, ls, lw=lw, color=colours[sec % len(colours)], label=name)
