"""Argument checks shared by every layer: numeric arrays of a given shape, homogeneous
poses, positive numbers.

Each raises a typed :class:`~softarm.errors.SoftarmError` naming the argument, so bad
input never surfaces as an error from deep inside numpy or OpenCV. This module imports
only numpy and :mod:`softarm.errors`, so :mod:`softarm.sim` and :mod:`softarm.vision` both
import it from below (see ``docs/architecture.md``, "Layers"). The image check
(``as_gray``, which needs OpenCV) stays in :mod:`softarm.vision._checks`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.errors import NonFiniteError, ParameterError, PoseError, ShapeError

__all__ = ["FloatArray", "as_array", "as_pose", "positive"]

FloatArray = npt.NDArray[np.float64]


def as_array(value: Any, shape: tuple[int | None, ...], name: str) -> FloatArray:
    """Convert ``value`` to float64 and check its shape (None = any length) and finiteness."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ShapeError(f"{name} must be numeric, got {value!r}") from exc
    if arr.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(arr.shape, shape, strict=True)
    ):
        want_str = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
        raise ShapeError(f"{name} must have shape {want_str}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise NonFiniteError(f"{name} contains NaN or infinite values")
    return arr


_EYE3 = np.eye(3)


def as_pose(value: Any, name: str, tol: float = 1e-6) -> FloatArray:
    """Check a 4x4 homogeneous pose: finite, last row [0, 0, 0, 1], rotation in SO(3)."""
    try:
        arr = as_array(value, (4, 4), name)
    except (ShapeError, NonFiniteError) as exc:
        raise PoseError(str(exc)) from exc
    # The tests of np.allclose(a, b, atol=tol), |a - b| <= tol + 1e-5 |b|, written out:
    # poses are checked wherever one is built, and allclose's general path costs ~100 µs.
    m = arr.tolist()
    last = zip(m[3], (0.0, 0.0, 0.0, 1.0), strict=True)
    if not all(abs(v - e) <= tol + 1e-5 * e for v, e in last):
        raise PoseError(f"{name} last row must be [0, 0, 0, 1], got {m[3]}")
    rot = arr[:3, :3]
    (a, b, c), (d, e, f), (g, h, k) = m[0][:3], m[1][:3], m[2][:3]
    det = a * (e * k - f * h) - b * (d * k - f * g) + c * (d * h - e * g)
    if not np.all(np.abs(rot.T @ rot - _EYE3) <= tol + 1e-5 * _EYE3) or det < 0.0:
        raise PoseError(f"{name} rotation block is not orthonormal with determinant +1")
    return np.ascontiguousarray(arr)


def positive(value: Any, name: str) -> float:
    """Return ``value`` as a finite float > 0 or raise :class:`ParameterError`."""
    try:
        out = float(value)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be a number, got {value!r}") from exc
    if not np.isfinite(out) or out <= 0.0:
        raise ParameterError(f"{name} must be finite and > 0, got {value!r}")
    return out
