"""The gripper's outline, shared by the matplotlib plots and the rerun view.

A two-jaw gripper in the end-effector frame: a palm across x at the frame's origin and two
fingers along z (the approach axis) that close on the grasp point ``offset`` ahead
(section III-D: the berry sits between the fingers, 3 cm ahead of the end effector).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import ParameterError, ShapeError

__all__ = ["gripper_outline", "gripper_polylines"]


#: Half the palm's width (m): the open jaws clear a 2 cm berry with room to spare.
HALF_PALM = 0.02


def gripper_outline(offset: float = 0.03) -> list[FloatArray]:
    """Polylines (each (n, 3), end-effector frame, m): the palm and the two fingers,
    whose tips reach ``offset`` / 3 past the grasp point."""
    if not np.isfinite(offset) or offset <= 0.0:
        raise ParameterError(f"offset must be a positive finite length (m), got {offset!r}")
    w, reach = HALF_PALM, offset * 4.0 / 3.0
    palm = np.array([[-w, 0.0, 0.0], [w, 0.0, 0.0]])
    fingers = [
        np.array([[s * w, 0.0, 0.0], [s * w, 0.0, 0.6 * reach], [s * 0.45 * w, 0.0, reach]])
        for s in (-1.0, 1.0)
    ]
    return [palm, *fingers]


def gripper_polylines(pose: npt.ArrayLike, offset: float = 0.03) -> list[FloatArray]:
    """:func:`gripper_outline` carried into the base frame by the 4x4 ``pose`` of the end
    effector."""
    T = np.asarray(pose, dtype=np.float64)
    if T.shape != (4, 4):
        raise ShapeError(f"pose must be a 4x4 matrix, got shape {T.shape}")
    return [line @ T[:3, :3].T + T[:3, 3] for line in gripper_outline(offset)]
