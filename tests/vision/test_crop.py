"""Rendering and detecting only the window that holds the markers (the fast simulated rig),
deferred edge refinement, and the OpenCV baselines with corner refinement."""

import pickle

import cv2
import numpy as np
import pytest

import softarm.sim.camera as sim_camera
from softarm.errors import ParameterError, VisionError
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker, cube_scene_markers
from softarm.sim.vision_scenes import facing_pose, random_cube_pose
from softarm.vision import CameraModel, MarkerCube, MarkerDetector, OpenCVBaseline
from softarm.vision.crop import ImageCrop
from softarm.vision.detector import default_parameters
from softarm.vision.refine import refine_marker_corners


def _scene(cube: MarkerCube, pose: np.ndarray) -> list[SceneMarker]:
    items = cube_scene_markers(cube.markers, cube.marker_length, cube.dictionary, pose)
    return [*items, SceneMarker(4, "DICT_4X4_50", 0.08, facing_pose(0.9, -0.3, 0.1))]


def test_crop_pixels_equal_the_full_frame_before_noise(
    camera: CameraModel, cube: MarkerCube
) -> None:
    full_cam = SyntheticCamera(camera, 1280, 720, supersample=2)
    crop_cam = SyntheticCamera(camera, 1280, 720, supersample=2)
    rng = np.random.default_rng(4)
    for _ in range(3):
        items = _scene(cube, random_cube_pose(rng))
        full, crop = full_cam.render(items), crop_cam.render_crop(items, margin=10)
        (x0, y0), (h, w) = crop.origin, crop.shape
        assert crop.full_size == (1280, 720) and 0 < h * w < full.size / 3
        np.testing.assert_array_equal(full[y0 : y0 + h, x0 : x0 + w], crop)
        outside = full.astype(int).copy()
        outside[y0 : y0 + h, x0 : x0 + w] = 128
        assert np.all(outside == 128)  # nothing was drawn outside the window


def test_ray_table_and_marker_cache_change_no_pixel(
    camera: CameraModel, cube: MarkerCube, monkeypatch: pytest.MonkeyPatch
) -> None:
    items = _scene(cube, random_cube_pose(np.random.default_rng(5)))
    fast = SyntheticCamera(camera, 1280, 720, supersample=2)
    first, again = fast.render(items), fast.render(items)  # the second from the cache
    monkeypatch.setattr(sim_camera, "MAX_RAY_TABLE_BYTES", 0)  # rays interpolated per box
    slow = SyntheticCamera(camera, 1280, 720, supersample=2)
    np.testing.assert_array_equal(first, again)
    np.testing.assert_array_equal(first, slow.render(items))
    moved = [
        SceneMarker(m.marker_id, m.dictionary, m.marker_length, m.T_camera_marker) for m in items
    ]
    moved[-1] = SceneMarker(4, "DICT_4X4_50", 0.08, facing_pose(0.9, -0.29, 0.1))
    assert not np.array_equal(fast.render(moved), first)  # a moved marker is drawn again


def test_crop_noise_has_the_frame_statistics(camera: CameraModel) -> None:
    cam = SyntheticCamera(camera, 1280, 720, noise_std=3.0, seed=5)
    items = [SceneMarker(2, "DICT_4X4_50", 0.2, facing_pose(0.5))]
    crop = np.asarray(cam.render_crop(items, margin=40), dtype=float)
    border = np.r_[crop[:30].ravel(), crop[-30:].ravel()]  # plain background, 128
    assert border.std() == pytest.approx(3.0, rel=0.05)
    assert border.mean() == pytest.approx(128.0, abs=0.1)


def test_detections_in_a_crop_are_in_frame_pixels(
    camera: CameraModel, renderer: SyntheticCamera, cube: MarkerCube
) -> None:
    rng = np.random.default_rng(6)
    items = _scene(cube, random_cube_pose(rng))
    full = renderer.render(items)
    detector = MarkerDetector()
    for x0, y0 in ((0, 0), (200, 100)):
        window = full[y0:, x0:]
        crop = ImageCrop(window, (x0, y0), (1280, 720))
        got = {d.marker_id: d.corners for d in detector.detect(crop, camera)}
        want = {d.marker_id: d.corners for d in detector.detect(full, camera)}
        assert sorted(got) == sorted(want)
        for i in want:
            # Only float32 rounding of OpenCV's sub-pixel step in other coordinates differs.
            np.testing.assert_allclose(got[i], want[i], atol=1e-4)


def test_crop_keeps_the_frame_perimeter_limits(camera: CameraModel) -> None:
    # OpenCV's minimum marker perimeter is a fraction of the image's larger side: in a small
    # crop the same fraction would admit markers the full frame rejects.
    params = default_parameters()
    params.minMarkerPerimeterRate = 0.2  # 256 px on the 1280 px frame
    detector = MarkerDetector(parameters=params)
    cam = SyntheticCamera(camera, 1280, 720, seed=1)
    small = [SceneMarker(3, "DICT_4X4_50", 0.05, facing_pose(0.9))]  # 50 px a side
    assert detector.detect(cam.render(small)) == []
    crop = cam.render_crop(small)
    assert max(crop.shape) < 256
    assert detector.detect(crop) == []
    assert [d.marker_id for d in MarkerDetector().detect(crop)] == [3]


def test_a_slice_of_a_crop_is_refused(renderer: SyntheticCamera) -> None:
    crop = renderer.render_crop([SceneMarker(1, "DICT_4X4_50", 0.08, facing_pose(0.7))])
    assert crop.copy().origin == crop.origin  # same window: the origin travels
    part = crop[5:, 5:]
    assert part.origin is None
    with pytest.raises(VisionError, match="origin"):
        MarkerDetector().detect(part)
    with pytest.raises(ParameterError, match="does not fit"):
        ImageCrop(np.zeros((10, 10), np.uint8), (1275, 0), (1280, 720))
    with pytest.raises(ParameterError, match="margin"):
        renderer.render_crop([], margin=-1)
    empty = renderer.render_crop([])
    assert empty.shape == (16, 16) and MarkerDetector().detect(empty) == []
    full = crop.full(128)
    assert full.shape == (720, 1280)
    back = pickle.loads(pickle.dumps(crop))
    assert back.origin == crop.origin and back.full_size == crop.full_size
    np.testing.assert_array_equal(back, crop)


def test_refinement_is_deferred_and_reads_a_copy(
    camera: CameraModel, renderer: SyntheticCamera
) -> None:
    pose = facing_pose(0.7, 0.05, -0.02)
    img = renderer.render([SceneMarker(7, "DICT_4X4_50", 0.08, pose)])
    plain = MarkerDetector(refine_edges=False).detect(img, camera)[0].corners
    want = refine_marker_corners(img, plain, camera, 6)
    (det,) = MarkerDetector().detect(img, camera)
    img[:] = 0  # the caller reuses its frame buffer before anyone reads the corners
    np.testing.assert_array_equal(det.corners, want)
    assert not np.array_equal(want, plain)
    img = renderer.render([SceneMarker(7, "DICT_4X4_50", 0.08, pose)])
    assert MarkerDetector().detect(img, camera) == MarkerDetector().detect(img, camera)


@pytest.mark.parametrize("refinement", ["none", "subpix", "apriltag"])
def test_opencv_baselines_with_corner_refinement(
    camera: CameraModel, renderer: SyntheticCamera, cube: MarkerCube, refinement: str
) -> None:
    baseline = OpenCVBaseline(cube, refinement)
    assert (
        baseline._detector.getDetectorParameters().cornerRefinementMethod
        == {
            "none": cv2.aruco.CORNER_REFINE_NONE,
            "subpix": cv2.aruco.CORNER_REFINE_SUBPIX,
            "apriltag": cv2.aruco.CORNER_REFINE_APRILTAG,
        }[refinement]
    )
    pose = random_cube_pose(np.random.default_rng(8))
    est = baseline.estimate_pose(renderer.render(_scene(cube, pose)[:4]), camera)
    assert est is not None and np.linalg.norm(est[:3, 3] - pose[:3, 3]) < 0.03


def test_baseline_refinement_is_checked(cube: MarkerCube) -> None:
    with pytest.raises(ParameterError, match="refinement"):
        OpenCVBaseline(cube, "contour-ish")


def test_window_around_chosen_markers_still_shows_the_others(camera: CameraModel) -> None:
    cam = SyntheticCamera(camera, 1280, 720, supersample=2)
    far = SceneMarker(1, "DICT_4X4_50", 0.08, facing_pose(0.8, -0.3, 0.0))
    near = SceneMarker(2, "DICT_4X4_50", 0.08, facing_pose(0.8, 0.25, 0.0))
    mine = SceneMarker(3, "DICT_4X4_50", 0.08, facing_pose(0.8, 0.15, 0.0))
    items = [far, near, mine]
    crop = cam.render_crop(items, around=lambda item: item is mine)
    assert crop.shape[1] < 300  # the window holds marker 3, not marker 1 far away
    (x0, y0), (h, w) = crop.origin, crop.shape
    # Marker 2 reaches into the window and is drawn there as in the whole frame.
    np.testing.assert_array_equal(cam.render(items)[y0 : y0 + h, x0 : x0 + w], crop)
    assert np.any(np.asarray(crop)[:, -5:] != 128)
    assert [d.marker_id for d in MarkerDetector().detect(crop)] == [3]
