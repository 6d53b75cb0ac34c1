"""Vision speed: detection + cube pose at 1280x720 (target ≥ 60 frames/s on one core),
the plain OpenCV baseline on the same frame, and the synthetic renderer."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker, cube_scene_markers
from softarm.sim.vision_scenes import facing_pose, random_cube_pose
from softarm.vision import CameraModel, MarkerCube, OpenCVBaseline

cv2.setNumThreads(1)  # one core, as the target is stated


@pytest.fixture(scope="module")
def setup() -> tuple[CameraModel, SyntheticCamera, MarkerCube, list, np.ndarray]:
    camera = CameraModel.ideal(900.0, 1280, 720, [-0.08, 0.03, 0.0005, -0.0005, 0.0])
    renderer = SyntheticCamera(camera, 1280, 720, noise_std=2.0, seed=1)
    cube = MarkerCube.standard()
    pose = random_cube_pose(np.random.default_rng(0))
    scene = cube_scene_markers(cube.markers, cube.marker_length, cube.dictionary, pose)
    scene.append(SceneMarker(20, "DICT_4X4_50", 0.1, facing_pose(1.2, -0.4, 0.25)))  # base tag
    return camera, renderer, cube, scene, renderer.render(scene)


def test_cube_pose_softarm(benchmark, setup) -> None:  # type: ignore[no-untyped-def]
    camera, _, cube, _, image = setup
    assert benchmark(cube.estimate_pose, image, camera) is not None


def test_cube_pose_opencv_baseline(benchmark, setup) -> None:  # type: ignore[no-untyped-def]
    camera, _, cube, _, image = setup
    baseline = OpenCVBaseline(cube)
    assert benchmark(baseline.estimate_pose, image, camera) is not None


def test_render_frame(benchmark, setup) -> None:  # type: ignore[no-untyped-def]
    _, renderer, _, scene, _ = setup
    assert benchmark(renderer.render, scene).shape == (720, 1280)
