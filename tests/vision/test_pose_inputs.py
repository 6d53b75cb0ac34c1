"""Pose estimation and intrinsic calibration on hostile input (issue 26, item 15): NaN
corners gave a NaN pose; collinear corners, three corners, and a camera with fx = 1e300
or k1 = 1e6 on a real marker image raised a raw ``cv2.error`` or ValueError, as did
``calibrate_chessboard`` with pattern (0, 0). Each is now one typed line."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import InputError, NonFiniteError, ShapeError, SoftarmError, VisionError
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker
from softarm.sim.vision_scenes import facing_pose as facing
from softarm.vision import (
    CameraModel,
    MarkerDetector,
    calibrate_charuco,
    calibrate_chessboard,
    estimate_marker_poses,
)
from softarm.vision.detector import Detection, square_marker_poses

LENGTH = 0.08


@pytest.fixture(scope="module")
def marker_image(clean_renderer: SyntheticCamera) -> np.ndarray:
    return clean_renderer.render([SceneMarker(7, "DICT_4X4_50", LENGTH, facing(0.6))])


@pytest.fixture(scope="module")
def detections(marker_image: np.ndarray) -> list[Detection]:
    found = MarkerDetector("DICT_4X4_50").detect(marker_image)
    assert [d.marker_id for d in found] == [7]
    return found


def _one_line(exc: BaseException) -> None:
    assert "\n" not in str(exc) and len(str(exc)) < 300


BAD_CORNERS = {
    "NaN": (np.full((4, 2), np.nan), NonFiniteError),
    "three corners": (np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]), ShapeError),
    "collinear": (np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]]), VisionError),
    "one point four times": (np.full((4, 2), 100.0), VisionError),
    "crossed": (np.array([[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]]), VisionError),
    "text": ([["a", "b"]] * 4, ShapeError),
}


@pytest.mark.parametrize("case", list(BAD_CORNERS))
def test_corners_that_are_no_marker_are_a_typed_error(case: str, camera: CameraModel) -> None:
    corners, error = BAD_CORNERS[case]
    with pytest.raises(error) as info:
        estimate_marker_poses([Detection(7, corners)], camera, LENGTH)
    _one_line(info.value)


def _with(camera: CameraModel, fx: float | None = None, k1: float | None = None) -> CameraModel:
    K, d = camera.matrix.copy(), camera.distortion.copy()
    if fx is not None:
        K[0, 0] = K[1, 1] = fx
    if k1 is not None:
        d[0] = k1
    return CameraModel(K, d, camera.image_size)


@pytest.mark.parametrize(("fx", "k1"), [(1e300, None), (None, 1e6), (1e-3, None)])
def test_an_absurd_camera_on_a_real_marker_is_a_typed_error_or_no_pose(
    camera: CameraModel, detections: list[Detection], fx: float | None, k1: float | None
) -> None:
    try:
        bad = _with(camera, fx, k1)
    except SoftarmError:
        return  # refused when the model is built: as good
    try:
        poses = estimate_marker_poses(detections, bad, LENGTH)
    except (VisionError, InputError) as exc:
        _one_line(exc)
        return
    assert all(np.all(np.isfinite(T)) for T in poses.values())


def test_a_real_marker_still_gives_its_pose(camera: CameraModel, detections: list[Detection]):
    (best, *_) = square_marker_poses(detections[0].corners, camera, LENGTH)
    np.testing.assert_allclose(best.T_camera_marker[:3, 3], facing(0.6)[:3, 3], atol=2e-3)


@pytest.mark.parametrize(
    "pattern", [(0, 0), (2, 5), (-1, 5), (10**400, 5), ("a", 5), (5,), 7, (5.5, 6), (True, 5)]
)
def test_a_bad_chessboard_pattern_is_an_input_error(
    pattern: object, marker_image: np.ndarray
) -> None:
    with pytest.raises(InputError, match=r"^pattern must be") as info:
        calibrate_chessboard([marker_image] * 3, pattern, 0.02)  # type: ignore[arg-type]
    _one_line(info.value)


def test_a_bad_charuco_board_is_an_input_error(marker_image: np.ndarray) -> None:
    with pytest.raises(InputError, match=r"^squares must be"):
        calibrate_charuco([marker_image] * 3, (0, 0), 0.04, 0.03)
