"""Shared fixtures: an eye-to-hand-like camera (1280x720, f = 900 px, mild distortion) and
its synthetic renderer, built once per session (the undistortion table takes ~0.5 s)."""

from __future__ import annotations

import pytest

from softarm.sim.camera import SyntheticCamera
from softarm.vision import CameraModel, MarkerCube

DISTORTION = [-0.08, 0.03, 0.0005, -0.0005, 0.0]


@pytest.fixture(scope="session")
def camera() -> CameraModel:
    return CameraModel.ideal(900.0, 1280, 720, DISTORTION)


@pytest.fixture(scope="session")
def renderer(camera: CameraModel) -> SyntheticCamera:
    return SyntheticCamera(camera, 1280, 720, noise_std=2.0, seed=7)


@pytest.fixture(scope="session")
def clean_renderer(camera: CameraModel) -> SyntheticCamera:
    return SyntheticCamera(camera, 1280, 720)


@pytest.fixture(scope="session")
def cube() -> MarkerCube:
    return MarkerCube.standard()
