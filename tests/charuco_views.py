"""Small ChArUco views for the calibration hardening tests, drawn by the numpy renderer
(:class:`softarm.sim.camera.SyntheticCamera`, no OpenGL): one camera, or a pair 12 cm
apart with the right eye on the left eye's +x."""

from __future__ import annotations

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import TexturedPlane
from softarm.vision import CameraModel
from softarm.vision.dictionaries import get_dictionary

BOARD = ((7, 5), 0.04, 0.03)
EYE = CameraModel.ideal(500.0, 640, 360, [-0.04, 0.01, 0.0, 0.0, 0.0])
BASELINE = 0.12
_PX, _MARGIN = 60, 30


def _texture() -> tuple[np.ndarray, float, float]:
    squares, square, marker = BOARD
    board = cv2.aruco.CharucoBoard(squares, square, marker, get_dictionary("DICT_4X4_50"))
    size = (squares[0] * _PX + 2 * _MARGIN, squares[1] * _PX + 2 * _MARGIN)
    tex = board.generateImage(size, marginSize=_MARGIN).astype(np.float32) / 255.0
    return tex, size[0] / _PX * square, size[1] / _PX * square


def board_poses(n: int, tilt: float = 0.5, seed: int = 4) -> list[np.ndarray]:
    """``n`` poses of the board in the left eye's frame, tilted by up to ``tilt`` rad
    (0: all facing the camera), in front of the pair's middle."""
    rng = np.random.default_rng(seed)
    poses = []
    for _ in range(n):
        pose = np.eye(4)
        turn = Rotation.from_rotvec(rng.uniform(-tilt, tilt, 3) * [1, 1, 0.3])
        pose[:3, :3] = (turn * Rotation.from_rotvec([np.pi, 0, 0])).as_matrix()
        pose[:3, 3] = [BASELINE / 2 + rng.uniform(-0.06, 0.06), rng.uniform(-0.03, 0.03),
                       rng.uniform(0.6, 0.7)]  # fmt: skip
        poses.append(pose)
    return poses


def render(poses: list[np.ndarray], eye: str = "left") -> list[np.ndarray]:
    """The BGR images of the board at ``poses`` seen by the ``eye`` ("left" or "right")."""
    tex, w, h = _texture()
    cam = SyntheticCamera(EYE, 640, 360, noise_std=1.0, supersample=2, seed=3)
    T_right_left = np.eye(4)
    T_right_left[0, 3] = -BASELINE if eye == "right" else 0.0
    images = []
    for pose in poses:
        grey = cam.render([TexturedPlane(tex, w, h, T_right_left @ pose)], background=90.0)
        images.append(cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR) if grey.ndim == 2 else grey)
    return images
