import numpy as np
import pytest

from softarm.errors import VisionError
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker
from softarm.sim.vision_scenes import facing_pose as facing
from softarm.sim.vision_scenes import random_facing_pose
from softarm.vision import CameraModel, MarkerDetector, estimate_marker_poses
from softarm.vision.detector import marker_object_points, square_marker_poses
from softarm.vision.poses import rotation_angle, transform_points


def test_detected_corners_match_projection(camera: CameraModel, renderer: SyntheticCamera) -> None:
    pose = facing(0.8, 0.1, -0.05)
    img = renderer.render([SceneMarker(7, "DICT_4X4_50", 0.08, pose)])
    (det,) = MarkerDetector().detect(img, camera)
    truth = camera.project(transform_points(pose, marker_object_points(0.08)))
    assert det.marker_id == 7
    assert np.max(np.linalg.norm(det.corners - truth, axis=1)) < 0.1  # px


def test_berry_tag_close_to_eye_in_hand_camera(
    camera: CameraModel, renderer: SyntheticCamera
) -> None:
    """A 12 mm berry tag 3–10 cm away: position error ≤ 0.5 mm (section III-D)."""
    rng = np.random.default_rng(11)
    detector = MarkerDetector()
    errors = []
    for _ in range(10):
        pose = random_facing_pose(rng, (0.03, 0.10))
        img = renderer.render([SceneMarker(5, "DICT_4X4_50", 0.012, pose)])
        est = estimate_marker_poses(detector.detect(img, camera), camera, 0.012)
        errors.append(np.linalg.norm(est[5][:3, 3] - pose[:3, 3]))
    assert max(errors) < 0.5e-3


def test_marker_orientation(camera: CameraModel, renderer: SyntheticCamera) -> None:
    rng = np.random.default_rng(12)
    pose = random_facing_pose(rng, (0.5, 0.6), max_angle_deg=40)
    img = renderer.render([SceneMarker(1, "DICT_4X4_50", 0.08, pose)])
    est = estimate_marker_poses(MarkerDetector().detect(img, camera), camera, 0.08)
    assert np.degrees(rotation_angle(est[1], pose)) < 1.0


def test_bgr_and_single_channel_frames(camera: CameraModel, renderer: SyntheticCamera) -> None:
    img = renderer.render([SceneMarker(2, "DICT_4X4_50", 0.08, facing(0.7))])
    detector = MarkerDetector()
    for frame in (np.dstack([img] * 3), np.dstack([img] * 4), img[:, :, None]):
        assert [d.marker_id for d in detector.detect(frame)] == [2]


@pytest.mark.parametrize(
    ("frame", "match"),
    [
        (None, "None"),
        (np.zeros((0, 0), np.uint8), "empty"),
        (np.zeros((10, 10), np.float32), "dtype"),
        (np.zeros((10, 10, 2), np.uint8), "shape"),
        ([[0, 1], [2, 3]], "numpy"),
    ],
)
def test_bad_frames_raise_vision_error(frame: object, match: str) -> None:
    with pytest.raises(VisionError, match=match):
        MarkerDetector().detect(frame)  # type: ignore[arg-type]


def test_no_markers_and_wrong_dictionary(renderer: SyntheticCamera) -> None:
    assert MarkerDetector().detect(np.full((720, 1280), 128, np.uint8)) == []
    img = renderer.render([SceneMarker(3, "DICT_6X6_50", 0.08, facing(0.6))])
    assert MarkerDetector("DICT_4X4_50").detect(img) == []
    assert [d.marker_id for d in MarkerDetector("DICT_6X6_50").detect(img)] == [3]


def test_exactly_frontal_marker_pose(camera: CameraModel) -> None:
    """IPPE degenerates for an exactly fronto-parallel square; the fallback must not."""
    pose = facing(0.8, 0.08)
    corners = camera.project(transform_points(pose, marker_object_points(0.08)))
    best = square_marker_poses(corners, camera, 0.08)[0]
    assert best.rms < 1e-3
    assert np.degrees(rotation_angle(best.T_camera_marker, pose)) < 0.1
