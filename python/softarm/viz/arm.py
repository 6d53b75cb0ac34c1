"""Drawing an arm's backbone and frames in 3-D."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from softarm._core import ArcChain, SoftArm

SECTION_COLOURS = ("tab:red", "tab:green", "tab:blue", "tab:purple", "tab:orange")


def draw_arm(
    ax: Any,
    arm: SoftArm | ArcChain,
    q: npt.ArrayLike,
    *,
    samples: int = 30,
    alpha: float = 1.0,
    frame_length: float = 0.03,
    label: str | None = None,
) -> None:
    """Draw the backbone of ``arm`` at ``q`` on a 3-D matplotlib axis, one colour per
    section (proximal red, medial green, distal blue as in the paper's figures), the rigid
    plate/gripper offsets as grey lines, and the end-effector frame."""
    pts = arm.backbone(q, samples).reshape(arm.n_sections, samples, 3)
    frames = arm.frames(q)
    for i in range(arm.n_sections):
        colour = SECTION_COLOURS[i % len(SECTION_COLOURS)]
        ax.plot(*pts[i].T, color=colour, lw=3, alpha=alpha, label=label if i == 0 else None)
        # Rigid offset from this arc's tip to the next frame's origin.
        ax.plot(*np.stack([pts[i, -1], frames[i + 1][:3, 3]]).T, color="0.5", lw=2, alpha=alpha)
    ee = frames[-1]
    for axis, colour in zip(range(3), ("r", "g", "b"), strict=True):
        tip = ee[:3, 3] + frame_length * ee[:3, axis]
        ax.plot(*np.stack([ee[:3, 3], tip]).T, color=colour, lw=1.5, alpha=alpha)


def set_equal_3d(ax: Any, points: npt.NDArray[np.float64]) -> None:
    """Equal scaling on a 3-D axis around ``points`` (N, 3)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-3)
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=True):
        setter(c - half, c + half)
