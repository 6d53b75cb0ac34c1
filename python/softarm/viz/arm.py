"""Drawing an arm's backbone and frames in 3-D."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from softarm._core import ArcChain, SoftArm
from softarm.checks import FloatArray

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


def clip_to_box(points: npt.ArrayLike, lo: npt.ArrayLike, hi: npt.ArrayLike) -> FloatArray:
    """A copy of ``points`` (n, 3) with those outside the box ``lo``..``hi`` set to NaN,
    which breaks the line there: matplotlib's 3-D axes do not clip to their limits."""
    pts = np.array(points, dtype=np.float64, ndmin=2)
    inside = np.all((pts >= np.asarray(lo) - 1e-9) & (pts <= np.asarray(hi) + 1e-9), axis=1)
    pts[~inside] = np.nan
    return pts


def arm_polylines(
    arm: SoftArm | ArcChain, q: npt.ArrayLike, samples: int = 20
) -> tuple[list[FloatArray], list[FloatArray]]:
    """The arm at ``q`` as lines: each section's arc ((samples, 3) points), and the rigid
    links ((2, 3): from each arc's tip to the next frame's origin, i.e. the plates and,
    after the last section, the gripper's body up to the end-effector frame)."""
    pts = np.asarray(arm.backbone(q, samples)).reshape(arm.n_sections, samples, 3)
    frames = arm.frames(q)
    links = [
        np.stack([pts[i, -1], np.asarray(frames[i + 1])[:3, 3]]) for i in range(arm.n_sections)
    ]
    return list(pts), links


def arm_line(arm: SoftArm | ArcChain, q: npt.ArrayLike, samples: int = 20) -> FloatArray:
    """The whole arm at ``q`` as one polyline from the base to the end-effector origin,
    rigid links included."""
    arcs, links = arm_polylines(arm, q, samples)
    return np.vstack([np.vstack([arc, link[1:]]) for arc, link in zip(arcs, links, strict=True)])
