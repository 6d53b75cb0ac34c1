"""C1's ray to a berry from both eyes (softarm.perception.two_eyes): the mean of the
left centre and the right one carried over by the disparity, the left one alone where
the right silhouette does not match it, and the ray's origin at the baseline's middle,
from which the triangulated berry lies in the direction of that mean."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from test_berry_centre import fruit_image

from softarm.perception import StereoCamera
from softarm.perception.berries import BerryDetection, detect_berries, fruit_mask
from softarm.perception.c1 import StereoC1
from softarm.perception.two_eyes import mean_centre, ray_origin
from softarm.vision.camera_model import CameraModel

CAMERA = CameraModel.ideal(300.0, 160, 120)
D = 30.0  # the disparity (px)


def _right(centre: tuple[float, float], hidden: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The right eye's blurred colour image and fruit mask with the fruit at ``centre``
    (its right half behind a leaf when ``hidden``)."""
    image = fruit_image(centre, 7.0, 0.0)
    if hidden:
        image[:, int(centre[0]) :] = (22, 30, 26)
    return cv2.GaussianBlur(image, (3, 3), 0), fruit_mask(image)


def _left() -> BerryDetection:
    [det] = detect_berries(fruit_image((80.3, 60.0), 7.0, 0.0), CAMERA)
    return det


def test_the_mean_of_both_eyes_centres() -> None:
    det = _left()
    assert det.center == pytest.approx((80.3, 60.0), abs=0.05)
    # The right eye sees it 0.4 px right of where the disparity carries the left centre.
    colour, mask = _right((80.3 - D + 0.4, 60.2))
    x, y = mean_centre(det, D, colour, mask)
    assert (x, y) == pytest.approx((80.3 + 0.2, 60.1), abs=0.05)


def test_the_left_centre_alone_when_the_right_silhouette_differs() -> None:
    det = _left()
    colour, mask = _right((80.3 - D, 60.0), hidden=True)
    assert mean_centre(det, D, colour, mask) == det.center
    # ...and when the right one is carried more than AGREE_PX from it (a wrong match).
    colour, mask = _right((80.3 - D + 1.6, 60.0))
    assert mean_centre(det, D, colour, mask) == det.center


def test_the_ray_from_the_baseline_middle_has_the_mean_direction() -> None:
    camera = CameraModel.ideal(900.0, 1280, 720)
    T_left_right = np.eye(4)
    T_left_right[0, 3] = 0.12
    T_base_left = np.eye(4)
    T_base_left[:3, 3] = (1.0, 2.0, 3.0)
    stereo = StereoCamera(camera, camera, T_base_left, T_left_right)
    np.testing.assert_allclose(ray_origin(stereo), (1.06, 2.0, 3.0), atol=1e-12)
    rect = stereo.rectification
    left, right = np.array([700.0, 300.0]), np.array([610.0, 300.0])
    d = 95.0  # not left - right: a disparity error moves the point along the ray only
    point = rect.triangulate(np.array([0.5 * (left + right + [d, 0.0])]), np.array([d]))[0]
    direction = point - 0.5 * T_left_right[:3, 3]
    mean = 0.5 * (left + right)
    cx, cy = rect.P1[0, 2], rect.P1[1, 2]
    expected = np.array([mean[0] - cx, mean[1] - cy, rect.focal])
    np.testing.assert_allclose(
        direction / np.linalg.norm(direction), expected / np.linalg.norm(expected), atol=1e-9
    )
    assert point[2] == pytest.approx(rect.focal * stereo.baseline / d)


def test_c1s_map_keeps_where_its_rays_start() -> None:
    camera = CameraModel.ideal(300.0, 160, 120)
    T_left_right = np.eye(4)
    T_left_right[0, 3] = 0.12
    stereo = StereoCamera(camera, camera, np.eye(4), T_left_right)
    blank = np.full((120, 160, 3), (60, 110, 70), np.uint8)
    c1 = StereoC1(stereo, lambda: (blank, blank))
    assert c1.bush_map.ray_origin is None
    c1.look()
    assert c1.bush_map.ray_origin is not None
    np.testing.assert_allclose(c1.bush_map.ray_origin, (0.06, 0.0, 0.0), atol=1e-12)
