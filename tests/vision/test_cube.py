import numpy as np
import pytest

from softarm.errors import ParameterError, VisionError
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker, cube_scene_markers
from softarm.sim.vision_scenes import facing_pose as facing
from softarm.sim.vision_scenes import random_cube_pose
from softarm.vision import CameraModel, CubeTracker, MarkerCube, OpenCVBaseline
from softarm.vision.detector import Detection, square_marker_poses
from softarm.vision.poses import rotation_angle, transform_points


def _scene(cube: MarkerCube, pose: np.ndarray) -> list[SceneMarker]:
    return cube_scene_markers(cube.markers, cube.marker_length, cube.dictionary, pose)


def test_standard_cube_geometry() -> None:
    cube = MarkerCube.standard(0.08)
    assert sorted(cube.markers) == [0, 1, 2, 3]
    for pose in cube.markers.values():
        assert np.linalg.norm(pose[:3, 3]) == pytest.approx(0.05)
        np.testing.assert_allclose(pose[:3, 2], pose[:3, 3] / 0.05)  # z out of the face
        np.testing.assert_allclose(pose[:3, 1], [0, 0, 1])


def test_pose_accuracy_and_better_than_opencv(
    camera: CameraModel, renderer: SyntheticCamera, cube: MarkerCube
) -> None:
    rng = np.random.default_rng(3)
    baseline = OpenCVBaseline(cube)
    ours, theirs, angles = [], [], []
    for _ in range(12):
        pose = random_cube_pose(rng)
        img = renderer.render(_scene(cube, pose))
        est = cube.estimate_pose(img, camera)
        ref = baseline.estimate_pose(img, camera)
        assert est is not None and ref is not None
        ours.append(np.linalg.norm(est[:3, 3] - pose[:3, 3]))
        theirs.append(np.linalg.norm(ref[:3, 3] - pose[:3, 3]))
        angles.append(np.degrees(rotation_angle(est, pose)))
    assert np.median(ours) < 1e-3
    assert np.median(angles) < 0.5
    assert np.median(ours) < np.median(theirs)


def test_single_face_pose_with_and_without_previous(camera: CameraModel, cube: MarkerCube) -> None:
    # One small, far, tilted face: weak perspective, so the mirrored (flipped) pose fits
    # the corners within the ambiguity tolerance and only the previous pose can decide.
    tilt = np.eye(4)
    c, s = np.cos(0.35), np.sin(0.35)
    tilt[:3, :3] = [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    pose = facing(4.0, 0.3) @ tilt @ np.linalg.inv(cube.markers[0])
    corners = camera.project(transform_points(pose, cube.object_points(0)))
    dets = [Detection(0, corners)]
    sols = square_marker_poses(corners, camera, cube.marker_length)
    flipped = sols[1].T_camera_marker @ np.linalg.inv(cube.markers[0])
    assert np.degrees(rotation_angle(flipped, pose)) > 20  # a genuinely different pose
    for prev in (None, pose):
        est = cube.estimate(dets, camera, previous=prev)
        assert est is not None
        assert np.degrees(rotation_angle(est.T_camera_cube, pose)) < 0.5
    # With the flip as the previous pose, a solution that fits the corners is still kept.
    est = cube.estimate(dets, camera, previous=flipped)
    assert est is not None and est.rms < 0.1


def test_tracker_feeds_back_previous_pose(
    camera: CameraModel, renderer: SyntheticCamera, cube: MarkerCube
) -> None:
    tracker = CubeTracker(cube, camera)
    pose = random_cube_pose(np.random.default_rng(8))
    assert tracker.update(np.full((720, 1280), 128, np.uint8)) is None
    est = tracker.update(renderer.render(_scene(cube, pose)))
    assert est is not None and tracker.last is est
    assert tracker.update(np.full((720, 1280), 128, np.uint8)) is None
    assert tracker.last is est
    tracker.reset()
    assert tracker.last is None


def test_no_cube_marker_gives_none(
    camera: CameraModel, renderer: SyntheticCamera, cube: MarkerCube
) -> None:
    img = renderer.render([SceneMarker(30, "DICT_4X4_50", 0.08, facing(0.8))])
    assert cube.estimate_pose(img, camera) is None
    wrong = renderer.render([SceneMarker(0, "DICT_5X5_50", 0.08, facing(0.8))])
    assert cube.estimate_pose(wrong, camera) is None
    with pytest.raises(VisionError):
        cube.estimate_pose(None, camera)


def test_bad_cube_definitions() -> None:
    with pytest.raises(ParameterError, match="markers"):
        MarkerCube({}, 0.08)
    with pytest.raises(ParameterError, match="marker id"):
        MarkerCube({99: np.eye(4)}, 0.08)
    with pytest.raises(ParameterError, match="cube_size"):
        MarkerCube.standard(0.08, cube_size=0.05)
    with pytest.raises(ParameterError, match="dictionary"):
        MarkerCube.standard(dictionary="DICT_NOPE")
