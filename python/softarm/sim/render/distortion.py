"""Lens distortion for rendered images: MuJoCo draws an ideal pinhole image; a real lens
bends it (OpenCV's model, the camera's ``distortion`` coefficients). Each output pixel
takes the pinhole pixel that its undistorted ray falls on (one ``cv2.remap`` per image,
the map made once per camera)."""

from __future__ import annotations

from typing import Any, cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.vision.camera_model import CameraModel

__all__ = ["Distorter"]


class Distorter:
    """Turns pinhole renders of ``camera`` (same matrix, no distortion) into images with
    its distortion. Colour is interpolated bilinearly; depth and labels take the
    nearest pixel, so no label or depth is invented along an edge."""

    def __init__(self, camera: CameraModel) -> None:
        self.identity = not np.any(camera.distortion)
        w, h = camera.image_size or (0, 0)
        u, v = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
        pixels = np.stack([u.ravel(), v.ravel()], axis=1).reshape(-1, 1, 2)
        ideal = cv2.undistortPoints(pixels, camera.matrix, camera.distortion, P=camera.matrix)
        self.map_x = ideal[:, 0, 0].reshape(h, w).astype(np.float32)
        self.map_y = ideal[:, 0, 1].reshape(h, w).astype(np.float32)

    def colour(self, image: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint8]:
        """The distorted colour image."""
        if self.identity:
            return image
        out = cv2.remap(image, self.map_x, self.map_y, cv2.INTER_LINEAR,
                        borderMode=cv2.BORDER_REPLICATE)  # fmt: skip
        return cast(npt.NDArray[np.uint8], out)  # remap keeps the source dtype

    def nearest(self, image: npt.NDArray[Any]) -> npt.NDArray[Any]:
        """The distorted depth or label image (nearest pixel)."""
        if self.identity:
            return image
        return cv2.remap(image, self.map_x, self.map_y, cv2.INTER_NEAREST,
                         borderMode=cv2.BORDER_REPLICATE)  # fmt: skip
