"""Cane points from two views of one camera (C2's survey pairs): against a cane drawn
into both views from its 3D line (closed form, no renderer), either view first, thinned
to another camera's footprint; bad inputs give a VisionError naming them."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.errors import VisionError
from softarm.perception.cane_views import view_pair_points
from softarm.vision.camera_model import CameraModel

CAMERA = CameraModel(
    np.array([[300.0, 0.0, 319.5], [0.0, 300.0, 239.5], [0.0, 0.0, 1.0]]),
    np.array([0.02, -0.01, 0.0, 0.0, 0.0]),
    (640, 480),
)
#: The cane: a 6 mm tube 25 cm in front of the first view, slanting across the image.
START, END, RADIUS = np.array([-0.06, -0.08, 0.25]), np.array([0.05, 0.08, 0.27]), 0.003
BROWN = np.array([40.0, 95.0, 120.0])  # BGR of bark in daylight (hue about 20)


def _pose(x: float, yaw_deg: float = 0.0) -> np.ndarray:
    """The camera ``x`` (m) along the first view's x axis, turned ``yaw_deg`` about y."""
    T = np.eye(4)
    T[:3, :3] = cv2.Rodrigues(np.array([0.0, np.radians(yaw_deg), 0.0]))[0]
    T[0, 3] = x
    return T


def _draw(T_base_camera: np.ndarray) -> np.ndarray:
    """The cane as ``CAMERA`` at ``T_base_camera`` sees it, on a grey-green backdrop;
    the bark darkens in bands along the cane, as seen from any view."""
    rng = np.random.default_rng(0)  # the same backdrop texture in both views
    image = np.clip(rng.normal(60.0, 6.0, (480, 640, 3)), 0, 255).astype(np.uint8)
    T = np.linalg.inv(T_base_camera)
    s = np.linspace(0.0, 1.0, 400)
    points = START + np.outer(s, END - START)
    camera = points @ T[:3, :3].T + T[:3, 3]
    pixels = cv2.projectPoints(camera, np.zeros(3), np.zeros(3), CAMERA.matrix, CAMERA.distortion)[
        0
    ]
    pixels = pixels.reshape(-1, 2)
    for k in range(len(s) - 1):
        width = max(1, round(2 * RADIUS * CAMERA.matrix[0, 0] / camera[k, 2]))
        shade = 0.75 + 0.25 * np.sin(2 * np.pi * s[k] * 12)
        a, b = np.round(pixels[k]).astype(int), np.round(pixels[k + 1]).astype(int)
        cv2.line(image, tuple(map(int, a)), tuple(map(int, b)), (BROWN * shade).tolist(), width)
    return image


def _distance_to_cane(points: np.ndarray) -> np.ndarray:
    d = (END - START) / np.linalg.norm(END - START)
    off = points - START
    return np.linalg.norm(off - np.outer(off @ d, d), axis=1)


@pytest.mark.parametrize("second_x", [0.05, -0.05])
def test_points_lie_on_the_cane_whichever_view_is_left(second_x: float) -> None:
    T_a, T_b = _pose(0.0), _pose(second_x, yaw_deg=2.0)
    points = view_pair_points(_draw(T_a), _draw(T_b), CAMERA, T_a, T_b)
    assert len(points) > 200
    # The drawing is a flat band on the centre line, where a tube's visible surface is
    # nearer: each point is pushed back by pi r / 4 (2.4 mm), which here overshoots.
    distance = _distance_to_cane(points[:, :3])
    assert np.median(distance) == pytest.approx(np.pi * RADIUS / 4, abs=0.0012)
    assert np.percentile(distance, 95) < 0.005
    assert np.median(points[:, 3]) == pytest.approx(RADIUS, abs=0.0015)


def test_points_are_thinned_to_the_footprint_of_a_farther_camera() -> None:
    T_a, T_b = _pose(0.0), _pose(0.05)
    a, b = _draw(T_a), _draw(T_b)
    full = view_pair_points(a, b, CAMERA, T_a, T_b)
    # A camera whose pixels are three times as large gives a ninth of the points.
    thinned = view_pair_points(a, b, CAMERA, T_a, T_b, footprint=3 * 0.26 / 300.0)
    assert len(thinned) == pytest.approx(len(full) / 9, rel=0.2)


def test_a_move_along_the_view_is_refused() -> None:
    T_a, T_b = _pose(0.0), _pose(0.0)
    T_b[2, 3] = 0.05
    with pytest.raises(VisionError, match="x axis"):
        view_pair_points(_draw(T_a), _draw(T_b), CAMERA, T_a, T_b)


@pytest.mark.parametrize(
    ("first", "second", "named"),
    [
        (np.zeros((480, 640), np.uint8), np.zeros((480, 640, 3), np.uint8), "first"),
        (np.zeros((480, 640, 3), np.uint8), np.zeros((480, 640, 3), np.float32), "second"),
        (np.zeros((240, 320, 3), np.uint8), np.zeros((480, 640, 3), np.uint8), "first"),
        (np.zeros((480, 640, 3), np.uint8), None, "second"),
    ],
)
def test_bad_images_are_named(first, second, named: str) -> None:
    with pytest.raises(VisionError, match=named):
        view_pair_points(first, second, CAMERA, _pose(0.0), _pose(0.05))


def test_black_views_give_no_points() -> None:
    black = np.zeros((480, 640, 3), np.uint8)
    assert view_pair_points(black, black, CAMERA, _pose(0.0), _pose(0.05)).shape == (0, 4)


def test_pixel_size_is_distance_over_focal_length() -> None:
    from softarm.perception.cane_views import pixel_size
    from softarm.vision.stereo_camera import StereoCamera

    eye = CameraModel(CAMERA.matrix, np.zeros(5), (640, 480))
    T_left_right = np.eye(4)
    T_left_right[0, 3] = 0.12
    T_base_left = np.eye(4)
    T_base_left[:3, 3] = [0.1, -0.2, 0.3]
    stereo = StereoCamera(eye, eye, T_base_left, T_left_right)
    point = T_base_left[:3, 3] + np.array([0.3, 0.4, 1.2])  # 1.3 m from the left eye
    assert pixel_size(stereo, point) == pytest.approx(1.3 / stereo.rectification.focal)
