"""Fixtures shared by the perception tests."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.vision.camera_model import CameraModel
from softarm.vision.stereo_camera import StereoCamera


@pytest.fixture(scope="module")
def stereo() -> StereoCamera:
    """A rectified 640 x 480 pair, f = 900 px, 12 cm baseline, the left eye at the base."""
    K = np.array([[900.0, 0, 320], [0, 900.0, 240], [0, 0, 1]])
    camera = CameraModel(K, np.zeros(5), image_size=(640, 480))
    T_left_right = np.eye(4)
    T_left_right[0, 3] = 0.12
    return StereoCamera(camera, camera, np.eye(4), T_left_right)
