import numpy as np
import pytest

from softarm.errors import ParameterError, PoseError
from softarm.sim.camera import Lighting, Scene, SyntheticCamera
from softarm.sim.markers import SceneMarker, TexturedPlane
from softarm.sim.vision_scenes import facing_pose
from softarm.vision import CameraModel, MarkerDetector
from softarm.vision.detector import marker_object_points
from softarm.vision.poses import transform_points


def test_plane_lands_where_the_model_projects_it() -> None:
    # Without distortion a frontal square images to a square: the rendered centroid of
    # darkness is the projected centre and its area the projected area. This pins the
    # pixel-centre convention (a half-pixel slip would show as 0.5 px).
    camera = CameraModel.ideal(900.0, 1280, 720)
    clean_renderer = SyntheticCamera(camera, 1280, 720)
    tex = np.ones((40, 40), np.float32)
    tex[10:30, 10:30] = 0.0
    pose = facing_pose(0.5, 0.05, 0.02)
    img = clean_renderer.render(Scene([TexturedPlane(tex, 0.2, 0.2, pose)], background=225.0))
    dark = (225.0 - img.astype(float)) / 200.0  # 1 inside the square (ink 25, paper 225)
    ys, xs = np.mgrid[0 : img.shape[0], 0 : img.shape[1]]
    centre = np.array([(dark * xs).sum(), (dark * ys).sum()]) / dark.sum()
    want = camera.project(transform_points(pose, [[0.0, 0.0, 0.0]]))[0]
    assert np.linalg.norm(centre - want) < 1e-3
    assert dark.sum() == pytest.approx((0.1 * 900 / 0.5) ** 2, rel=1e-4)


def test_back_faces_are_culled_and_near_planes_occlude(
    clean_renderer: SyntheticCamera,
) -> None:
    back = facing_pose(0.6) @ np.diag([1.0, -1.0, -1.0, 1.0])  # turned away from the camera
    img = clean_renderer.render([SceneMarker(1, "DICT_4X4_50", 0.08, back)], background=100.0)
    assert np.all(img == 100)
    far = SceneMarker(1, "DICT_4X4_50", 0.08, facing_pose(1.0))
    near = SceneMarker(2, "DICT_4X4_50", 0.08, facing_pose(0.5))
    for order in ([far, near], [near, far]):
        ids = [d.marker_id for d in MarkerDetector().detect(clean_renderer.render(order))]
        assert ids == [2]


def test_noise_is_seeded_and_has_the_requested_std(camera: CameraModel) -> None:
    a = SyntheticCamera(camera, 1280, 720, noise_std=3.0, seed=5).render([], background=128.0)
    b = SyntheticCamera(camera, 1280, 720, noise_std=3.0, seed=5).render([], background=128.0)
    np.testing.assert_array_equal(a, b)
    assert a.astype(float).std() == pytest.approx(3.0, rel=0.05)
    assert a.astype(float).mean() == pytest.approx(128.0, abs=0.05)


def test_blur_and_lighting_keep_markers_detectable(camera: CameraModel) -> None:
    light = Lighting(
        black=40.0, white=200.0, ambient=0.4, light_direction=(0.3, -0.3, -1.0), vignetting=0.3
    )
    cam = SyntheticCamera(camera, 1280, 720, noise_std=2.0, blur=1.0, lighting=light, seed=2)
    pose = facing_pose(0.9, -0.2, 0.1)
    img = cam.render([SceneMarker(4, "DICT_4X4_50", 0.08, pose)])
    (det,) = MarkerDetector().detect(img, camera)
    truth = camera.project(transform_points(pose, marker_object_points(0.08)))
    assert np.max(np.abs(det.corners - truth)) < 0.15


def test_bad_parameters(camera: CameraModel) -> None:
    with pytest.raises(ParameterError, match="width"):
        SyntheticCamera(camera, 0, 720)
    with pytest.raises(ParameterError, match="noise_std"):
        SyntheticCamera(camera, 10, 10, noise_std=-1.0)
    with pytest.raises(ParameterError, match="supersample"):
        SyntheticCamera(camera, 10, 10, supersample=0)
    with pytest.raises(ParameterError, match="marker id"):
        SceneMarker(50, "DICT_4X4_50", 0.08, np.eye(4))
    with pytest.raises(PoseError, match="T_camera_marker"):
        SceneMarker(1, "DICT_4X4_50", 0.08, np.zeros((4, 4)))
