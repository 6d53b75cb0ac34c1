"""Perception on the arm (issue 24, item 2): with ``[perception]`` the hardware rig
reads C1 from the stereo source (a ZED2's side-by-side frame, or a pair), builds its
bush map with the code the rendered bush runs, hands the fitted canes to the control
stack and finds the berries without tags. The devices are faked at the boundary; the
rendered test feeds the rig the rendered bush's own stereo frames."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from softarm._core import PolynomialCurve
from softarm.errors import ConfigError, ParameterError
from softarm.hardware.simulated import SimulatedCamera
from softarm.harvest.control import stack as rig
from softarm.harvest.rigs.hardware import devices as hw_devices
from softarm.harvest.rigs.hardware import rig as hw_rig
from softarm.perception.bush_vision import BushVision
from softarm.perception_config import PerceptionConfig
from softarm.vision import CameraModel
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import StereoCamera
from softarm.vision.stereo_files import write_stereo

from .test_hw_rig_config import _config, no_devices  # noqa: F401  (the fixture)

os.environ.setdefault("MUJOCO_GL", "egl")


def _perceiving(folder: Path, model: StereoCamera, **kwargs: Any) -> Any:
    """The test config with ``[perception]``, its stereo.yml written in ``folder``."""
    write_stereo(model, folder / "stereo.yml")
    perception = PerceptionConfig(folder=str(folder), **kwargs)
    return replace(_config(), perception=perception)


def _ideal_pair() -> StereoCamera:
    cam = CameraModel.ideal(500.0, 320, 240)
    T = np.eye(4)
    T[0, 3] = 0.12
    return StereoCamera.pair(cam, cam, T)


@pytest.fixture
def opened(monkeypatch: pytest.MonkeyPatch) -> dict[Any, Any]:
    """The frames each OpenCV source gives (set by the test), and what was opened."""
    frames: dict[Any, Any] = {}

    def camera(source: Any) -> SimulatedCamera:
        frames.setdefault("opened", []).append(source)
        return SimulatedCamera(lambda: frames.get(source))

    monkeypatch.setattr(hw_devices, "OpenCVCamera", camera)
    return frames


@pytest.fixture
def canes_given(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The canes each control stack was built with."""
    given: list[Any] = []

    def record(cfg: Any, inputs: Any, canes: Any, *args: Any) -> rig.ControlStack:
        given.append(list(canes))
        return rig.build_control_stack(cfg, inputs, canes, *args)

    monkeypatch.setattr(hw_rig, "build_control_stack", record)
    return given


@pytest.mark.usefixtures("no_devices")
def test_a_zed2_is_one_device_split_and_the_berries_are_markerless(
    tmp_path: Path, opened: dict[Any, Any], canes_given: list[Any]
) -> None:
    config = _perceiving(tmp_path, _ideal_pair(), stereo="zed2", device=3)
    opened[3] = np.zeros((240, 640, 3), np.uint8)  # nothing in view
    opened[1] = np.zeros((240, 320, 3), np.uint8)
    built = hw_rig.build_hardware_rig(config)
    try:
        assert opened["opened"] == [3, 1]  # the ZED2, then C2; no C1 camera of its own
        assert isinstance(built.machine.vision, BushVision) and built.markerless
        assert built.machine.vision.model1 is built.c1.stereo.left  # type: ignore[union-attr]
        assert canes_given == [[]]
        # C2's detection of a markerless berry needs the whole standoff to settle.
        assert built.machine.planner.near_standoff == 0.0  # type: ignore[union-attr]
        report = built.run(2)  # an empty map: nothing to pick
        assert report.berries == [] and report.stopped is None
    finally:
        built.close()


@pytest.mark.usefixtures("no_devices")
def test_a_pair_is_two_devices_and_tags_keep_the_tag_vision(
    tmp_path: Path, opened: dict[Any, Any]
) -> None:
    config = _perceiving(tmp_path, _ideal_pair(), stereo="pair", left=4, right=5, berries="tags")
    opened.update({k: np.zeros((240, 320, 3), np.uint8) for k in (4, 5, 1)})
    built = hw_rig.build_hardware_rig(config)
    try:
        assert opened["opened"] == [4, 5, 1]
        assert not isinstance(built.machine.vision, BushVision) and not built.markerless
        near = built.machine.planner.near_standoff  # type: ignore[union-attr]
        assert near == built.machine.config.near_standoff > 0
    finally:
        built.close()


@pytest.mark.usefixtures("no_devices")
def test_a_missing_stereo_file_names_the_key(tmp_path: Path) -> None:
    config = replace(_config(), perception=PerceptionConfig(folder=str(tmp_path)))
    with pytest.raises(ConfigError, match=r"perception\.calibration") as err:
        hw_rig.build_hardware_rig(config)
    assert "\n" not in str(err.value)


@pytest.fixture(scope="module")
def bush() -> Any:
    """A small rendered bush (the sim rig's own map and canes), or a skip (a failure
    where the render is required)."""
    from render_required import rendering
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    with rendering():
        return build_sim_rig(SimRigOptions(n_berries=3, seed=330, world="bush"))


@pytest.mark.usefixtures("no_devices")
def test_the_rig_perceives_the_rendered_bush_as_the_simulator_does(
    tmp_path: Path, opened: dict[Any, Any], canes_given: list[Any], bush: Any
) -> None:
    scene = bush.scene
    stereo = scene.c1()
    model = StereoCamera.pair(stereo.left, stereo.right, stereo.T_left_right)
    config = _perceiving(tmp_path, model, stereo="zed2", device=0)
    pose = tuple(tuple(r) for r in invert(stereo.T_base_left).tolist())
    config = replace(config, calibration=replace(config.calibration, T_C1_base=pose))
    left, right = scene.world.c1()
    opened[0] = np.hstack([left.colour, right.colour])
    built = hw_rig.build_hardware_rig(config)
    try:
        mine = sorted(tuple(np.round(b.position, 9)) for b in built.c1.bush_map.berries)  # type: ignore[union-attr]
        sims = sorted(tuple(np.round(b.position, 9)) for b in scene.bush_map.berries)
        assert mine and mine == sims
        assert len(canes_given[0]) >= len(scene.bush_map.canes) > 0
    finally:
        built.close()


@pytest.mark.usefixtures("no_devices")
def test_given_canes_with_the_survey_on_are_refused_not_a_silent_survey_off(
    tmp_path: Path,
) -> None:
    config = _perceiving(tmp_path, _ideal_pair(), stereo="zed2", device=3)
    cane = PolynomialCurve(np.array([[0.0, 0.1, 0, 0], [0.4, 0, 0, 0], [0.3, 0, 0, 0]]), (0, 1))
    with pytest.raises(ParameterError, match=r"canes: .*survey = false"):
        hw_rig.build_hardware_rig(config, canes=[cane])
