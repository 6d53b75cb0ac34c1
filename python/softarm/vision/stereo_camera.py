"""A calibrated stereo pair (C1, the ZED2) and its rectification.

``T_left_right`` is the right eye's pose in the left eye's frame (OpenCV axes), so a
point maps as ``x_left = T_left_right @ x_right``. Rectification (``cv2.stereoRectify``)
turns both eyes so that their rows align: a point's two images then differ only by the
disparity d along the row, and its depth in the rectified left frame is z = f B / d.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray, as_pose
from softarm.errors import VisionError
from softarm.vision.camera_model import CameraModel
from softarm.vision.poses import invert

__all__ = ["Rectification", "StereoCamera"]


@dataclass(frozen=True)
class StereoCamera:
    """Both eyes' intrinsics (with image sizes), the left eye in the base frame and the
    right eye in the left eye's frame.

    Checked when built, not at the first rectification: both poses finite 4x4 rigid
    transforms (a rotation scaled x5 would put every berry five times as far), and
    the right eye to the left eye's right, along its +x axis (an eye on -x, from
    swapped eyes, would put berries behind the camera).

    Raises:
        VisionError: an eye is not a CameraModel with an image size, or the right
            eye is not mostly along the left eye's +x axis.
        PoseError: ``T_base_left`` or ``T_left_right`` is not a finite 4x4 pose with
            an orthonormal rotation.
    """

    left: CameraModel
    right: CameraModel
    T_base_left: FloatArray
    T_left_right: FloatArray

    def __post_init__(self) -> None:
        for name in ("left", "right"):
            if not isinstance(getattr(self, name), CameraModel):
                got = type(getattr(self, name)).__name__
                raise VisionError(f"{name} must be a CameraModel, got {got}")
        if self.left.image_size is None or self.right.image_size is None:
            raise VisionError("a stereo camera needs both eyes' image_size")
        for name in ("T_base_left", "T_left_right"):
            object.__setattr__(self, name, as_pose(getattr(self, name), name))
        if self.baseline <= 0:
            raise VisionError("a stereo camera needs two distinct optical centres")
        x, y, z = self.T_left_right[:3, 3]
        if x <= max(abs(y), abs(z)):
            raise VisionError(
                f"T_left_right puts the right eye at {[float(x), float(y), float(z)]} m: it "
                "must lie mostly along the left eye's +x axis (eyes swapped?)"
            )

    @classmethod
    def pair(
        cls, left: CameraModel, right: CameraModel, T_left_right: npt.ArrayLike
    ) -> StereoCamera:
        """The pair alone, as a calibration gives it: its left eye at the base frame's
        origin (place it with :meth:`placed`)."""
        return cls(left, right, np.eye(4), np.asarray(T_left_right, dtype=np.float64))

    def placed(self, T_base_left: npt.ArrayLike) -> StereoCamera:
        """The same pair with its left eye at ``T_base_left`` in the base frame."""
        return replace(self, T_base_left=np.asarray(T_base_left, dtype=np.float64))

    @property
    def baseline(self) -> float:
        """Distance (m) between the two optical centres."""
        return float(np.linalg.norm(self.T_left_right[:3, 3]))

    @cached_property
    def rectification(self) -> Rectification:
        """The rectification of this pair (computed once)."""
        return Rectification(self)


class Rectification:
    """Rectifying maps, projections and the disparity-to-depth matrix of a pair."""

    def __init__(self, stereo: StereoCamera) -> None:
        size = stereo.left.image_size
        assert size is not None  # checked by StereoCamera
        T_right_left = invert(stereo.T_left_right)
        R = np.ascontiguousarray(T_right_left[:3, :3])
        T = np.ascontiguousarray(T_right_left[:3, 3]).reshape(3, 1)
        L, Rm = stereo.left, stereo.right
        R1, R2, P1, P2, Q, _, _ = cv2.stereoRectify(
            L.matrix, L.distortion, Rm.matrix, Rm.distortion, size, R, T, alpha=0,
            flags=cv2.CALIB_ZERO_DISPARITY,
        )  # fmt: skip
        self.size = size
        self._left = L
        # float64, as stereoRectify returns them (its stubs say any number array).
        self.R1, self.P1 = cast(FloatArray, R1), cast(FloatArray, P1)
        self.P2, self.Q = cast(FloatArray, P2), cast(FloatArray, Q)
        self.focal = float(P1[0, 0])
        self.baseline = stereo.baseline
        self.maps = [
            cast(
                tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]],
                cv2.initUndistortRectifyMap(c.matrix, c.distortion, r, p, size, cv2.CV_32FC1),
            )
            for c, r, p in ((L, R1, P1), (Rm, R2, P2))
        ]

    def rectify(
        self, left: npt.NDArray[np.uint8], right: npt.NDArray[np.uint8]
    ) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
        """Both images resampled onto the rectified grid."""
        (mx_l, my_l), (mx_r, my_r) = self.maps
        return (
            cast(npt.NDArray[np.uint8], cv2.remap(left, mx_l, my_l, cv2.INTER_LINEAR)),
            cast(npt.NDArray[np.uint8], cv2.remap(right, mx_r, my_r, cv2.INTER_LINEAR)),
        )

    def to_rectified_pixels(self, pixels: FloatArray) -> FloatArray:
        """(N, 2) distorted left-eye pixels → their rectified pixels."""
        pts = np.asarray(pixels, dtype=np.float64).reshape(-1, 1, 2)
        L = self._left
        out = cv2.undistortPoints(pts, L.matrix, L.distortion, R=self.R1, P=self.P1)
        return cast(FloatArray, out).reshape(-1, 2)

    def triangulate(self, left_px: FloatArray, disparity: npt.ArrayLike) -> FloatArray:
        """(N, 3) points in the (unrectified) left camera frame from rectified left pixels
        (N, 2) and their disparities (N,) in pixels: z = f B / d (the rectified frame),
        then turned back by R1ᵀ."""
        d = np.asarray(disparity, dtype=np.float64)
        pts = np.column_stack([left_px, d, np.ones_like(d)]) @ self.Q.T
        rect = pts[:, :3] / pts[:, 3:4]
        return rect @ self.R1  # R1ᵀ applied to each row
