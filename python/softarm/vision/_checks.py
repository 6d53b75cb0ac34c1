"""Input validation shared by the vision modules.

Every public entry point checks its arguments here, so that bad input surfaces as a typed
:class:`~softarm.errors.SoftarmError` naming the argument, never as a ``cv2.error`` from
deep inside OpenCV.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import NonFiniteError, PoseError, ShapeError, VisionError

FloatArray = npt.NDArray[np.float64]
ImageArray = npt.NDArray[np.uint8]


def as_gray(image: Any, name: str = "image") -> ImageArray:
    """Return ``image`` as a C-contiguous 2-D uint8 array, converting BGR/BGRA to gray.

    Raises :class:`VisionError` for None, empty, non-uint8 or oddly shaped frames.
    """
    if image is None:
        raise VisionError(f"{name} is None: no frame was captured")
    if not isinstance(image, np.ndarray):
        raise VisionError(f"{name} must be a numpy array, got {type(image).__name__}")
    if image.size == 0:
        raise VisionError(f"{name} is empty (shape {image.shape})")
    if image.dtype != np.uint8:
        raise VisionError(f"{name} must have dtype uint8, got {image.dtype}")
    if image.ndim == 3 and image.shape[2] == 1:
        image = image[:, :, 0]
    if image.ndim == 2:
        return np.ascontiguousarray(image)
    if image.ndim == 3 and image.shape[2] in (3, 4):
        # Shape and dtype are vetted above, so cvtColor cannot fail on layout.
        code = cv2.COLOR_BGR2GRAY if image.shape[2] == 3 else cv2.COLOR_BGRA2GRAY
        return np.asarray(cv2.cvtColor(np.ascontiguousarray(image), code), dtype=np.uint8)
    raise VisionError(f"{name} must be (H, W) gray or (H, W, 3|4) BGR(A), got shape {image.shape}")


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
    from softarm.errors import ParameterError

    try:
        out = float(value)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be a number, got {value!r}") from exc
    if not np.isfinite(out) or out <= 0.0:
        raise ParameterError(f"{name} must be finite and > 0, got {value!r}")
    return out
