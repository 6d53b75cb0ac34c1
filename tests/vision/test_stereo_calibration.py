"""Stereo calibration recovers the intrinsics and the baseline of a rendered pair: one
ChArUco board seen by two cameras 12 cm apart (MuJoCo, ``MUJOCO_GL=egl``), with known
intrinsics and lens distortion (issue 24: fx within 0.5 %, baseline within 1 mm)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm.errors import InputError, ParameterError, VisionError
from softarm.vision import CameraModel
from softarm.vision.stereo_calibration import calibrate_stereo_charuco, split_side_by_side
from softarm.vision.stereo_camera import StereoCamera

BOARD = ((9, 6), 0.04, 0.03)
LEFT = CameraModel.ideal(1000.0, 1280, 720, [-0.05, 0.02, 0.0, 0.0, 0.0])
RIGHT = CameraModel(
    np.array([[1010.0, 0.0, 645.0], [0.0, 1010.0, 355.0], [0.0, 0.0, 1.0]]),
    np.array([-0.04, 0.015, 0.0, 0.0, 0.0]),
    (1280, 720),
)
BASELINE = 0.12


def _T_left_right() -> np.ndarray:
    """The right eye 12 cm along the left eye's x, toed in by 0.01 rad."""
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_euler("y", 0.01).as_matrix()
    pose[0, 3] = BASELINE
    return pose


@pytest.fixture(scope="module")
def views() -> tuple[list[np.ndarray], list[np.ndarray]]:
    """12 simultaneous (left, right) views of the board in front of the pair."""
    from render_required import rendering
    from softarm.sim.render.charuco import BoardSpec, CharucoScene, board_poses

    spec = BoardSpec(*BOARD)
    with rendering():
        scene = CharucoScene(spec, {"left": (LEFT, np.eye(4)), "right": (RIGHT, _T_left_right())})
        shots = [scene.render(T) for T in board_poses(spec, 12, seed=1, centre=(0.06, 0.0))]
    scene.close()
    return [s["left"] for s in shots], [s["right"] for s in shots]


def test_recovers_the_intrinsics_and_the_baseline(
    views: tuple[list[np.ndarray], list[np.ndarray]],
) -> None:
    model, rms = calibrate_stereo_charuco(*views, *BOARD)
    assert rms < 0.3
    for got, truth in ((model.left, LEFT), (model.right, RIGHT)):
        assert got.matrix[0, 0] == pytest.approx(truth.matrix[0, 0], rel=0.005)
        assert got.matrix[1, 1] == pytest.approx(truth.matrix[1, 1], rel=0.005)
        np.testing.assert_allclose(got.matrix[:2, 2], truth.matrix[:2, 2], atol=3.0)
        assert got.image_size == (1280, 720)
    assert model.baseline == pytest.approx(BASELINE, abs=1e-3)
    np.testing.assert_allclose(model.T_left_right[:3, 3], [BASELINE, 0, 0], atol=1e-3)
    rot = Rotation.from_matrix(model.T_left_right[:3, :3] @ _T_left_right()[:3, :3].T)
    assert rot.magnitude() < 1e-3


def test_side_by_side_frames_calibrate_the_same(
    views: tuple[list[np.ndarray], list[np.ndarray]],
) -> None:
    frames = [np.hstack(pair) for pair in zip(*views, strict=True)]
    halves = [split_side_by_side(f) for f in frames]
    model, _ = calibrate_stereo_charuco([h[0] for h in halves], [h[1] for h in halves], *BOARD)
    assert model.baseline == pytest.approx(BASELINE, abs=1e-3)


def test_the_calibrated_pair_is_placed_in_the_base_frame(
    views: tuple[list[np.ndarray], list[np.ndarray]],
) -> None:
    model, _ = calibrate_stereo_charuco(*views, *BOARD)
    np.testing.assert_array_equal(model.T_base_left, np.eye(4))
    T_base_left = np.eye(4)
    T_base_left[:3, 3] = [0.1, -1.2, 0.4]
    placed = model.placed(T_base_left)
    np.testing.assert_array_equal(placed.T_base_left, T_base_left)
    np.testing.assert_array_equal(placed.T_left_right, model.T_left_right)
    assert placed.baseline == model.baseline


def test_stereo_files_round_trip(
    views: tuple[list[np.ndarray], list[np.ndarray]], tmp_path: Path
) -> None:
    from softarm.vision.stereo_files import read_stereo, write_ros_stereo, write_stereo

    model, _ = calibrate_stereo_charuco(*views, *BOARD)
    write_stereo(model, tmp_path / "stereo.yml")
    back = read_stereo(tmp_path / "stereo.yml")
    np.testing.assert_allclose(back.T_left_right, model.T_left_right, atol=1e-12)
    assert back.left == model.left and back.right == model.right
    write_ros_stereo(model, tmp_path / "left.yaml", tmp_path / "right.yaml")
    assert CameraModel.load(tmp_path / "right.yaml") == model.right
    text = (tmp_path / "right.yaml").read_text()
    assert "camera_name: right" in text and "rectification_matrix" in text


def test_bad_input_is_one_typed_error() -> None:
    blank = [np.full((720, 1280), 128, np.uint8)] * 3
    with pytest.raises(InputError, match="pair up"):
        calibrate_stereo_charuco(blank, blank[:2], *BOARD)
    with pytest.raises(VisionError, match="left_images: calibration needs >= 3"):
        calibrate_stereo_charuco(blank, blank, *BOARD)
    with pytest.raises(VisionError, match="right_images\\[1\\]"):
        calibrate_stereo_charuco(blank[:2], [blank[0], None], *BOARD)  # type: ignore[list-item]
    with pytest.raises(ParameterError, match="marker_length"):
        calibrate_stereo_charuco(blank, blank, (9, 6), 0.03, 0.04)
    with pytest.raises(VisionError, match="even width"):
        split_side_by_side(np.zeros((4, 5), np.uint8))


def test_the_model_checks_its_pose() -> None:
    from softarm.errors import PoseError

    with pytest.raises(PoseError):
        StereoCamera.pair(LEFT, RIGHT, np.zeros((4, 4)))
