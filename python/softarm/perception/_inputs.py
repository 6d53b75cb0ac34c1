"""Argument checks of the perception entry points: colour frames, depth images, settings
and camera models, each refused with a :class:`~softarm.errors.VisionError` (images)
or an :class:`~softarm.errors.InputError` naming the argument, so that bad input never
surfaces as a ``cv2.error``, a numpy error or a silently wrong result.

One place for them, so that :func:`~softarm.perception.berries.detect_berries`,
:func:`~softarm.perception.stereo.locate_berries` and
:func:`~softarm.perception.canes.fit_canes` agree on what they accept.
"""

from __future__ import annotations

from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

from softarm.errors import InputError, VisionError

__all__ = ["MAX_FRAME_PIXELS", "bgr_image", "depth_metres", "instance", "instance_or_default"]

#: The largest colour frame (pixels) perception reads: 4096 x 4096, twice a 4K UHD frame.
#: Every step is linear in the pixels (the berry detector takes about 1.6 s on one core
#: at this size, 0.1 s at 1280 x 720), so a larger frame (8000 x 8000: 12 s) is refused
#: rather than read: downscale it, and its calibration with it, first.
MAX_FRAME_PIXELS = 4096 * 4096

T = TypeVar("T")


def _describe(value: object) -> str:
    if isinstance(value, np.ndarray):
        return f"a {value.dtype} array of shape {value.shape}"
    return "None" if value is None else f"a {type(value).__name__}"


def bgr_image(
    value: object, name: str, size: tuple[int, int] | None = None
) -> npt.NDArray[np.uint8]:
    """``value`` as an (H, W, 3) uint8 BGR frame of at most MAX_FRAME_PIXELS pixels and,
    when ``size`` = (width, height) is given (a calibration's image size), of that size.

    Raises:
        VisionError: naming ``name``: None, not an array, empty, another dtype or
            shape (grey, BGRA), too large, or not the calibrated size.
    """
    if value is None:
        raise VisionError(f"{name} is None: no image was captured")
    if not isinstance(value, np.ndarray):
        raise VisionError(f"{name} must be a numpy BGR image array, got {_describe(value)}")
    if value.dtype != np.uint8:
        raise VisionError(
            f"{name} must be a uint8 image (BGR as OpenCV reads it), got {_describe(value)}"
        )
    if value.ndim != 3 or value.shape[2] != 3 or min(value.shape[:2]) == 0:
        raise VisionError(f"{name} must be an (H, W, 3) BGR image, got shape {value.shape}")
    height, width = value.shape[:2]
    if height * width > MAX_FRAME_PIXELS:
        raise VisionError(
            f"{name} is {width}x{height}: larger than {MAX_FRAME_PIXELS} pixels, the most "
            "perception reads (downscale it, and its calibration, first)"
        )
    if size is not None and (width, height) != tuple(size):
        raise VisionError(
            f"{name} is {width}x{height} but its calibration's image_size is "
            f"{size[0]}x{size[1]}: give frames of the calibrated size"
        )
    return value


def depth_metres(
    value: object, shape: tuple[int, ...], name: str = "depth"
) -> npt.NDArray[np.floating[Any]] | None:
    """``value`` (None, or an (H, W) float array of depths in metres, 0 or NaN where
    unknown) checked against an image of ``shape`` (H, W, ...).

    A uint16 depth image (millimetres, as ``softarm dataset`` writes it) is refused with
    the conversion to make, not read as metres (every fruit 1000 times too far); bool,
    complex, text, object and datetime arrays are refused.

    Raises:
        VisionError: naming ``name``: not an array, not float, or not (H, W).
    """
    if value is None:
        return None
    if not isinstance(value, np.ndarray):
        raise VisionError(f"{name} must be an (H, W) float array in metres, got {_describe(value)}")
    if value.dtype == np.uint16:
        raise VisionError(
            f"{name} is uint16 (millimetres, as `softarm dataset` writes it): give metres, "
            f"e.g. {name}.astype(np.float32) / 1000 (0 stays unknown)"
        )
    if value.dtype.kind != "f":
        raise VisionError(f"{name} must be a float array in metres, got {_describe(value)}")
    if value.shape != tuple(shape[:2]):
        raise VisionError(
            f"{name} must be an (H, W) array of shape {tuple(shape[:2])} like its image, "
            f"got shape {value.shape}"
        )
    return value


def instance_or_default(value: object, cls: type[T], name: str) -> T:
    """``value`` when it is a ``cls``, ``cls()`` when it is None.

    Raises:
        InputError: naming ``name``: anything else (a string, a dict of settings).
    """
    if value is None:
        return cls()
    if not isinstance(value, cls):
        raise InputError(f"{name} must be a {cls.__name__} or None, got {_describe(value)}")
    return value


def instance(value: object, cls: type[T], name: str) -> T:
    """``value`` when it is a ``cls``.

    Raises:
        InputError: naming ``name``: anything else (None, a path, a dict).
    """
    if not isinstance(value, cls):
        raise InputError(f"{name} must be a {cls.__name__}, got {_describe(value)}")
    return value
