"""Snapshots of a planned motion, like the planning paper's figures 3-5."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from softarm import _core
from softarm.planning.scenarios import Scenario


def snapshot_iterations(plan: _core.Plan, count: int = 3) -> list[int]:
    """Iterations to draw: the first, evenly spaced ones, and the last."""
    last = plan.iterations
    return sorted({int(round(v)) for v in np.linspace(0, last, count)})


def plot_plan(scenario: Scenario, plan: _core.Plan, out: str | Path, title: str = "") -> Path:
    """Draws the curves, the goal and the arm at a few iterations, one panel each."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    chain = scenario.chain
    iters = snapshot_iterations(plan)
    fig = plt.figure(figsize=(4.2 * len(iters), 4.4))
    us = np.linspace(0.0, 1.0, 200)
    for k, it in enumerate(iters):
        ax = fig.add_subplot(1, len(iters), k + 1, projection="3d")
        for curve in scenario.curves:
            lo, hi = curve.u_range
            pts = curve(lo + (hi - lo) * us)
            ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], color="tab:brown", lw=2)
        q = plan.path[it]
        bb = chain.backbone(q, 30)
        for sec in range(chain.n_sections):
            part = bb[30 * sec : 30 * (sec + 1)]
            ax.plot(part[:, 0], part[:, 1], part[:, 2], lw=3, color=f"C{sec}")
        tips = plan.tip_path[: it + 1]
        ax.plot(tips[:, 0], tips[:, 1], tips[:, 2], ":", color="gray", lw=1)
        g = scenario.goal
        ax.scatter([g[0]], [g[1]], [g[2]], marker="*", s=120, color="red")
        ax.set_xlim(-0.5, 2.0)
        ax.set_ylim(-1.2, 1.8)
        ax.set_zlim(0.0, 3.0)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_zlabel("z (m)")
        label = "final iteration" if it == plan.iterations else f"{it} iterations"
        ax.set_title(f"({chr(97 + k)}) {label}")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    out = Path(out)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
