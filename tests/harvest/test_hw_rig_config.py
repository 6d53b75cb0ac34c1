"""The hardware rig takes its harvest tuning, cube mount and berry tag size from the
configuration file, with the devices replaced by the simulated backends."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from softarm.config import default_config
from softarm.hardware.simulated import (
    IdealPlant,
    SimulatedCamera,
    SimulatedGripper,
    SimulatedPressureBank,
    SimulatedRipenessSensor,
)
from softarm.harvest import HarvestConfig
from softarm.harvest.rigs.hardware import devices as hw_devices
from softarm.harvest.rigs.hardware import rig as hw_rig


class _Link:
    def __init__(self, *args: object, **kwargs: object) -> None:
        pass

    def close(self) -> None:
        pass


@pytest.fixture
def no_devices(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(
        hw_devices, "NidaqPressureBank", lambda names, vmap: SimulatedPressureBank(IdealPlant())
    )
    monkeypatch.setattr(hw_devices, "ArduinoLink", _Link)
    monkeypatch.setattr(hw_devices, "OpenCVCamera", lambda source: SimulatedCamera(lambda: None))
    monkeypatch.setattr(hw_rig, "ArduinoGripper", lambda link: SimulatedGripper())
    monkeypatch.setattr(hw_rig, "ArduinoRipenessSensor", lambda link: SimulatedRipenessSensor())


def _config():
    c = default_config()
    eye = tuple(tuple(r) for r in np.eye(4).tolist())
    k = ((900.0, 0.0, 640.0), (0.0, 900.0, 360.0), (0.0, 0.0, 1.0))
    cube = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, -0.07), (0, 0, 0, 1.0))
    cal = replace(
        c.calibration,
        T_C1_base=eye,
        T_C2_EE=eye,
        c1=replace(c.calibration.c1, matrix=k),
        c2=replace(c.calibration.c2, matrix=k),
        T_EE_cube=cube,
        berry_tag=0.02,
    )
    return replace(c, calibration=cal, harvest=HarvestConfig(period=0.1, grasp_offset=0.04))


@pytest.mark.usefixtures("no_devices")
def test_the_rig_is_tuned_and_built_from_the_config() -> None:
    config = _config()
    rig = hw_rig.build_hardware_rig(config)
    try:
        m = rig.machine
        assert m.config is config.harvest
        assert m.vision.berry_tag == 0.02
        assert m.vision.T_ee_cube[2, 3] == -0.07
        assert m.vision.fusion.tool_point[2] == 0.04  # the grasp point of [harvest]
    finally:
        rig.close()


@pytest.mark.usefixtures("no_devices")
def test_an_explicit_tuning_overrides_the_config() -> None:
    tuning = HarvestConfig(period=0.02)
    rig = hw_rig.build_hardware_rig(_config(), tuning)
    try:
        assert rig.machine.config is tuning
    finally:
        rig.close()
