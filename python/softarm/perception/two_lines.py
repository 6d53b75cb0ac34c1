"""Where two lines of sight pass nearest each other: the one owner of that formula,
for C1's sight line against C2's ray (:mod:`softarm.perception.sight_lines`) and for
C2's gate and fix along C1's ray (:mod:`softarm.perception.approach`)."""

from __future__ import annotations

import numpy as np

from softarm.checks import FloatArray

__all__ = ["MIN_CROSSING", "closest_params"]

#: Rays crossing at less than this angle (rad) leave the depth undetermined.
MIN_CROSSING = np.radians(15.0)


def closest_params(
    o1: FloatArray, u1: FloatArray, o2: FloatArray, u2: FloatArray
) -> tuple[float, float] | None:
    """The parameters (s, t) of the closest points ``o1 + s u1`` and ``o2 + t u2`` of
    two lines with unit directions ``u1``, ``u2`` (the 2x2 normal equations), or None
    where they cross at less than MIN_CROSSING."""
    b = float(u1 @ u2)
    if 1.0 - b * b < np.sin(MIN_CROSSING) ** 2:
        return None
    w = o1 - o2
    s = (b * float(u2 @ w) - float(u1 @ w)) / (1.0 - b * b)
    t = (float(u2 @ w) - b * float(u1 @ w)) / (1.0 - b * b)
    return s, t
