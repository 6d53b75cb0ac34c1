"""Small SE(3) helpers: Rodrigues vectors to 4x4 poses and back, inverse, angle distance."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray


def pose_from_rvec_tvec(rvec: npt.ArrayLike, tvec: npt.ArrayLike) -> FloatArray:
    """4x4 pose from an OpenCV rotation vector and translation (object in camera frame)."""
    pose = np.eye(4)
    # cv2.Rodrigues: the same map as scipy's from_rotvec, ~20x cheaper per call.
    rot, _ = cv2.Rodrigues(np.asarray(rvec, dtype=np.float64).reshape(3, 1))
    pose[:3, :3] = rot
    pose[:3, 3] = np.asarray(tvec, dtype=np.float64).reshape(3)
    return pose


def rvec_tvec_from_pose(pose: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """OpenCV (rvec, tvec), each (3, 1) float64, from a 4x4 pose."""
    arr = np.asarray(pose, dtype=np.float64)
    rvec, _ = cv2.Rodrigues(np.ascontiguousarray(arr[:3, :3]))
    return np.asarray(rvec, dtype=np.float64).reshape(3, 1), arr[:3, 3].reshape(3, 1).copy()


def invert(pose: npt.ArrayLike) -> FloatArray:
    """Inverse of a rigid 4x4 transform (uses Rᵀ, not a general matrix inverse)."""
    arr = np.asarray(pose, dtype=np.float64)
    out = np.eye(4)
    out[:3, :3] = arr[:3, :3].T
    out[:3, 3] = -arr[:3, :3].T @ arr[:3, 3]
    return out


def rotation_angle(a: npt.ArrayLike, b: npt.ArrayLike) -> float:
    """Geodesic angle (rad) between the rotation blocks of two poses or 3x3 rotations."""
    ra = np.asarray(a, dtype=np.float64)[:3, :3]
    rb = np.asarray(b, dtype=np.float64)[:3, :3]
    cos = (np.trace(ra.T @ rb) - 1.0) / 2.0
    return float(np.arccos(np.clip(cos, -1.0, 1.0)))


def transform_points(pose: npt.ArrayLike, points: npt.ArrayLike) -> FloatArray:
    """Apply a 4x4 pose to (N, 3) points."""
    arr = np.asarray(pose, dtype=np.float64)
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return pts @ arr[:3, :3].T + arr[:3, 3]
