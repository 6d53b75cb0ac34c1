"""Input validation shared by the vision modules: the image check here, the rest
re-exported from :mod:`softarm.checks`.

Every public entry point checks its arguments here, so that bad input surfaces as a typed
:class:`~softarm.errors.SoftarmError` naming the argument, never as a ``cv2.error`` from
deep inside OpenCV.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

# The checks that need no OpenCV live in softarm.checks (sim imports them from there).
from softarm.checks import FloatArray, as_array, as_pose, positive
from softarm.errors import VisionError

__all__ = ["FloatArray", "ImageArray", "as_array", "as_gray", "as_pose", "positive"]
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
