"""Stereo calibration files: one OpenCV FileStorage file for the pair, and a ROS
``camera_info`` YAML per eye.

**OpenCV** (``stereo.yml``), the keys of OpenCV's stereo calibration sample
(``samples/cpp/stereo_calib.cpp``) in one file: ``image_width``, ``image_height``,
``M1``/``D1`` and ``M2``/``D2`` (left and right intrinsics), ``R``/``T`` (the left eye's
points in the right eye's frame: ``x_right = R x_left + T``, metres), and
``T_left_right`` (4×4, its inverse: softarm's convention).

**ROS** (``left.yaml``, ``right.yaml``), as ``camera_calibration`` writes a stereo pair:
each eye's intrinsics, its rectification rotation and its rectified projection (the
right one carries ``-fx B`` in ``P[0, 3]``). softarm reads either eye back as a camera
(:meth:`CameraModel.load`, which ignores the rectification).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import cv2
import numpy as np

from softarm.errors import ConfigError
from softarm.files import read_text, write_text
from softarm.vision.calibration_checks import pair_problems
from softarm.vision.camera_files import (
    _ROS_MODELS,
    _cv_reason,
    _open,
    _ros_matrix,
    _size,
    memory_storage,
)
from softarm.vision.camera_model import CameraModel
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["read_stereo", "write_ros_stereo", "write_stereo"]


def write_stereo(model: StereoCamera, path: str | Path) -> None:
    """Write ``model`` as one OpenCV FileStorage file (see the module docstring)."""
    T_right_left = invert(model.T_left_right)
    size = model.left.image_size or (0, 0)
    fs = memory_storage(path, "stereo file")
    fs.write("image_width", int(size[0]))
    fs.write("image_height", int(size[1]))
    for key, value in _matrices(model, T_right_left).items():
        fs.write(key, np.asarray(value, dtype=np.float64))
    write_text(path, fs.releaseAndGetString(), "stereo file")


def _matrices(model: StereoCamera, T_right_left: np.ndarray) -> dict[str, Any]:
    return {
        "M1": model.left.matrix,
        "D1": model.left.distortion.reshape(-1, 1),
        "M2": model.right.matrix,
        "D2": model.right.distortion.reshape(-1, 1),
        "R": T_right_left[:3, :3],
        "T": T_right_left[:3, 3].reshape(3, 1),
        "T_left_right": model.T_left_right,
    }


def read_stereo(path: str | Path) -> StereoCamera:
    """The pair of a ``stereo.yml`` that :func:`write_stereo` wrote, checked as the
    harvest will use it: finite matrices of the right shapes, ``R``/``T`` (when given)
    agreeing with ``T_left_right``, and a plausible pair
    (:func:`~softarm.vision.calibration_checks.pair_problems`: a baseline of 5 mm to 2 m,
    the right eye on the left eye's +x).

    Raises:
        ConfigError: the file is missing, empty or unparsable, lacks a key, or holds a
            value the harvest cannot use (one line, the key named).
    """
    text = read_text(path, "stereo file")
    fs = _open(path, text.lstrip("\ufeff \t\r\n"), "stereo file")
    try:
        mats = {k: _mat(fs, k, path, shape) for k, shape in _SHAPES.items()}
        extra = {k: _mat(fs, k, path, shape, required=False) for k, shape in _R_T.items()}
        size = _size(fs, path)
    finally:
        fs.release()
    where = f"stereo file {str(path)!r}"
    if size is None:
        raise ConfigError(f"{where}: image_width and image_height are missing")
    _agree(mats["T_left_right"], extra, where)
    problems = pair_problems(mats["T_left_right"])
    if problems:
        raise ConfigError(f"{where}: T_left_right: {problems[0]}")
    try:
        return StereoCamera.pair(
            CameraModel(mats["M1"], mats["D1"].ravel(), size),
            CameraModel(mats["M2"], mats["D2"].ravel(), size),
            mats["T_left_right"],
        )
    except ValueError as exc:
        raise ConfigError(f"{where}: {exc}") from None


#: The keys read and their shapes (None: any number of rows, one column).
_SHAPES: dict[str, tuple[int, int] | None] = {
    "M1": (3, 3), "D1": None, "M2": (3, 3), "D2": None, "T_left_right": (4, 4)
}  # fmt: skip
_R_T: dict[str, tuple[int, int] | None] = {"R": (3, 3), "T": (3, 1)}
#: How far R and T may lie from the inverse of T_left_right (rotation entries, m): the
#: file holds both at 16 significant digits.
_AGREE = 1e-6


def _mat(
    fs: Any, key: str, path: str | Path, shape: tuple[int, int] | None, required: bool = True
) -> Any:
    """The finite matrix ``key`` of ``shape``; None when it is absent and not required."""
    where = f"stereo file {str(path)!r}: {key}"
    node = fs.getNode(key)
    if node.isNone() and not required:
        return None
    try:
        mat = None if node.isNone() or not node.isMap() else node.mat()
    except cv2.error as exc:
        raise ConfigError(f"{where} is not a valid opencv-matrix ({_cv_reason(exc)})") from None
    if mat is None:
        raise ConfigError(f"{where} is missing or not a matrix")
    mat = np.asarray(mat, dtype=np.float64)
    if mat.shape != (shape or (mat.shape[0], 1)):
        want = "one column" if shape is None else f"{shape[0]}x{shape[1]}"
        raise ConfigError(f"{where} must be {want}, got shape {mat.shape}")
    if not np.all(np.isfinite(mat)):
        raise ConfigError(f"{where} holds a value that is not finite (nan or inf)")
    return mat


def _agree(T_left_right: np.ndarray, extra: dict[str, Any], where: str) -> None:
    """``R`` and ``T`` (the left eye in the right eye's frame), when both are given,
    must be the inverse of ``T_left_right``: the harvest reads only the latter."""
    if extra["R"] is None or extra["T"] is None:
        return
    T_right_left = invert(T_left_right)
    off_r = float(np.max(np.abs(T_right_left[:3, :3] - extra["R"])))
    off_t = float(np.max(np.abs(T_right_left[:3, 3] - extra["T"].ravel())))
    if off_r > _AGREE or off_t > _AGREE:
        raise ConfigError(
            f"{where}: R and T contradict T_left_right (off by {off_r:.3g} in rotation, "
            f"{off_t:.3g} m): they must be its inverse; fix or remove them"
        )


def write_ros_stereo(model: StereoCamera, left: str | Path, right: str | Path) -> None:
    """Write each eye as a ROS ``camera_info`` YAML with its rectification and rectified
    projection (``cv2.stereoRectify``), named ``left`` and ``right``."""
    size = model.left.image_size
    if size is None:
        raise ConfigError("a ROS camera_info file needs the image size")
    T = invert(model.T_left_right)
    L, R = model.left, model.right
    R1, R2, P1, P2, *_ = cv2.stereoRectify(
        L.matrix, L.distortion, R.matrix, R.distortion, size,
        np.ascontiguousarray(T[:3, :3]), T[:3, 3].reshape(3, 1).copy(), alpha=0,
        flags=cv2.CALIB_ZERO_DISPARITY,
    )  # fmt: skip
    for path, name, cam, rect, proj in ((left, "left", L, R1, P1), (right, "right", R, R2, P2)):
        write_text(path, _ros_text(cam, name, rect, proj), "camera file")


def _ros_text(cam: CameraModel, name: str, rect: np.ndarray, proj: np.ndarray) -> str:
    dist = np.asarray(cam.distortion, dtype=np.float64)
    if dist.size in (0, 4):
        dist = np.concatenate([dist, np.zeros(5 - dist.size)])
    if dist.size not in _ROS_MODELS:
        raise ConfigError(f"ROS camera_info has no distortion model with {dist.size} values")
    width, height = cam.image_size or (0, 0)
    lines = [
        f"image_width: {int(width)}",
        f"image_height: {int(height)}",
        f"camera_name: {name}",
        *_ros_matrix("camera_matrix", cam.matrix),
        f"distortion_model: {_ROS_MODELS[dist.size]}",
        *_ros_matrix("distortion_coefficients", dist.reshape(1, -1)),
        *_ros_matrix("rectification_matrix", np.asarray(rect, dtype=np.float64)),
        *_ros_matrix("projection_matrix", np.asarray(proj, dtype=np.float64)),
    ]
    return "\n".join(lines) + "\n"
