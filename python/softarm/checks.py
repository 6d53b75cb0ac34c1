"""Argument checks shared by every layer: numeric arrays of a given shape, homogeneous
poses, positive numbers.

Each raises a typed :class:`~softarm.errors.SoftarmError` naming the argument, so bad
input never surfaces as an error from deep inside numpy or OpenCV. This module imports
only numpy and :mod:`softarm.errors`, so :mod:`softarm.sim` and :mod:`softarm.vision` both
import it from below (see ``docs/architecture.md``, "Layers"). The image check
(``as_gray``, which needs OpenCV) stays in :mod:`softarm.vision._checks`.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.errors import NonFiniteError, ParameterError, PoseError, ShapeError

__all__ = ["FloatArray", "as_array", "as_pose", "finite_real", "numeric_array", "positive"]

FloatArray = npt.NDArray[np.float64]

#: numpy kinds that are numbers: signed and unsigned integers, floats. Not text ("U",
#: "S": numpy would parse "1" as 1.0), not complex ("c": the cast drops the imaginary
#: part with only a warning), not bool.
_NUMERIC_KINDS = "iuf"


def _short(value: Any) -> str:
    """``repr(value)`` cut to one short line for a message (a 400-digit int, a big list)."""
    text = repr(value).replace("\n", " ")
    return text if len(text) <= 60 else text[:57] + "..."


def _real_objects(arr: npt.NDArray[Any], value: Any, name: str) -> FloatArray:
    """An object array (Python ints too large for int64, mixed types) as float64: every
    element a real number, none beyond the float range."""
    for item in arr.flat:
        if isinstance(item, bool | np.bool_) or not isinstance(item, numbers.Real):
            raise ShapeError(f"{name} must be numeric, got {_short(value)}")
    try:
        return arr.astype(np.float64)
    except OverflowError:
        raise NonFiniteError(f"{name} has a number beyond the float range") from None


def numeric_array(value: Any, name: str) -> FloatArray:
    """``value`` as a float64 array, from numbers only: text, bytes, complex, bool,
    dicts and ragged lists are a :class:`ShapeError` naming ``name``, an integer beyond
    the float range (a 400-digit int) a :class:`NonFiniteError`. Shape and finiteness
    are the caller's (:func:`as_array`)."""
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError, OverflowError, RecursionError):
        raise ShapeError(f"{name} must be numeric, got {_short(value)}") from None
    if arr.dtype.kind == "O":
        return _real_objects(arr, value, name)
    if arr.dtype.kind not in _NUMERIC_KINDS:
        raise ShapeError(f"{name} must be numeric, got {_short(value)}")
    return arr.astype(np.float64)


def as_array(value: Any, shape: tuple[int | None, ...], name: str) -> FloatArray:
    """Convert ``value`` to float64 (:func:`numeric_array`) and check its shape (None =
    any length) and finiteness."""
    arr = numeric_array(value, name)
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


def finite_real(value: Any) -> bool:
    """Whether ``value`` is a finite int or float (not a bool, a string or an array):
    the check of a settings field that must be a number as given, not one parsed."""
    return (
        isinstance(value, int | float) and not isinstance(value, bool) and bool(np.isfinite(value))
    )
