"""A window of a larger camera image, for detectors that only need part of the frame.

An :class:`ImageCrop` is a numpy image (so every image function accepts it) that also
knows where it lies in the full frame: array pixel (r, c) is full-frame pixel
(r + y0, c + x0), with ``origin = (x0, y0)`` and ``full_size = (width, height)``.
:meth:`~softarm.vision.MarkerDetector.detect` returns full-frame corners for it, so the
camera model (principal point, distortion) applies unchanged. The simulated cameras render
only the window that holds the markers (:meth:`~softarm.sim.SyntheticCamera.render_crop`).

The window travels only with arrays of the same height and width (a copy, arithmetic on
the pixels); a slice of different shape is a crop whose ``origin`` is None, i.e. unknown,
and the detector then refuses it rather than report corners in the wrong place.
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError

__all__ = ["ImageCrop"]


class ImageCrop(np.ndarray):
    """``pixels`` (H, W[, C]) seen at ``origin`` = (x0, y0) of a ``full_size`` =
    (width, height) frame. Raises :class:`~softarm.errors.ParameterError` if the window
    does not lie inside the frame."""

    origin: tuple[int, int] | None = None
    full_size: tuple[int, int] | None = None

    def __new__(
        cls, pixels: npt.ArrayLike, origin: tuple[int, int], full_size: tuple[int, int]
    ) -> ImageCrop:
        arr = np.asarray(pixels)
        if arr.ndim not in (2, 3):
            raise ParameterError(f"pixels must be an (H, W) or (H, W, C) image, got {arr.shape}")
        x0, y0 = (int(v) for v in origin)
        width, height = (int(v) for v in full_size)
        h, w = arr.shape[:2]
        if x0 < 0 or y0 < 0 or x0 + w > width or y0 + h > height:
            raise ParameterError(
                f"a {w}x{h} crop at origin {(x0, y0)} does not fit in a {width}x{height} "
                f"frame (origin={origin!r}, full_size={full_size!r})"
            )
        obj = arr.view(cls)
        obj.origin, obj.full_size = (x0, y0), (width, height)
        return obj

    def __array_finalize__(self, obj: Any) -> None:
        if obj is None:
            return
        same = getattr(obj, "shape", (None, None))[:2] == self.shape[:2]
        self.origin = getattr(obj, "origin", None) if same else None
        self.full_size = getattr(obj, "full_size", None) if same else None

    def __reduce__(self) -> tuple[Any, ...]:
        # ndarray pickles its pixels only: carry the window along.
        ctor, args, state = cast(tuple[Any, ...], super().__reduce__())[:3]
        return ctor, args, (state, self.origin, self.full_size)

    def __setstate__(self, state: Any) -> None:
        pixels, self.origin, self.full_size = state
        super().__setstate__(pixels)

    def full(self, fill: float = 0.0) -> npt.NDArray[Any]:
        """The full frame as a plain array: this window pasted on ``fill``."""
        if self.origin is None or self.full_size is None:
            raise ParameterError("this crop has lost its origin (it is a slice of a crop)")
        (x0, y0), (width, height) = self.origin, self.full_size
        out = np.full((height, width, *self.shape[2:]), fill, dtype=self.dtype)
        out[y0 : y0 + self.shape[0], x0 : x0 + self.shape[1]] = np.asarray(self)
        return out
