"""Vision speed: detection + cube pose at 1280x720 (target ≥ 60 frames/s on one core),
the plain OpenCV baseline on the same frame, and the synthetic renderer: whole frames, and
the simulated rig's way (supersample 2, only the window holding the markers, detection in
that window)."""

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


@pytest.fixture(scope="module")
def moving(setup):  # type: ignore[no-untyped-def]
    """A rig-like camera (supersample 2) and 50 cube poses, so that no frame repeats a
    marker's pose (a repeated pose would be drawn from the renderer's cache)."""
    camera, _, cube, scene, _ = setup
    renderer = SyntheticCamera(camera, 1280, 720, noise_std=2.0, supersample=2, seed=1)
    rng = np.random.default_rng(1)
    scenes = []
    for _ in range(50):
        pose = random_cube_pose(rng)
        markers = cube_scene_markers(cube.markers, cube.marker_length, cube.dictionary, pose)
        scenes.append([*markers, scene[-1]])
    return camera, renderer, cube, scenes


def _cycle(render, scenes):  # type: ignore[no-untyped-def]
    state = {"i": 0}

    def one():  # type: ignore[no-untyped-def]
        state["i"] = (state["i"] + 1) % len(scenes)
        return render(scenes[state["i"]])

    return one


def test_render_frame_rig(benchmark, moving) -> None:  # type: ignore[no-untyped-def]
    _, renderer, _, scenes = moving
    assert benchmark(_cycle(renderer.render, scenes)).shape == (720, 1280)


def test_render_crop_rig(benchmark, moving) -> None:  # type: ignore[no-untyped-def]
    _, renderer, _, scenes = moving
    assert benchmark(_cycle(renderer.render_crop, scenes)).full_size == (1280, 720)


def test_cube_pose_in_crop(benchmark, moving) -> None:  # type: ignore[no-untyped-def]
    camera, renderer, cube, scenes = moving
    crop = renderer.render_crop(scenes[0])
    assert benchmark(cube.estimate_pose, crop, camera) is not None
