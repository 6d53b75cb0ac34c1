"""The hardware rig: the same state machine on the real devices, from a TOML config.

Devices are opened in the order of the bring-up (pressure outputs behind the safety
layer, the Arduino for gripper and ripeness sensor, both cameras); if one is missing
everything opened so far is vented and closed again and
:class:`~softarm.errors.HardwareUnavailableError` says which device and why.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import ExitStack
from dataclasses import dataclass

import numpy as np

from softarm._core import PolynomialCurve, Section, SoftArm
from softarm.calibration.result import Calibration
from softarm.config import Config
from softarm.errors import ConfigError
from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.arduino_devices import ArduinoGripper, ArduinoRipenessSensor
from softarm.hardware.camera import OpenCVCamera
from softarm.hardware.clock import MonotonicClock
from softarm.hardware.daq import NidaqPressureBank
from softarm.hardware.pressure_map import ElongationMap, VoltageMap
from softarm.hardware.safety import SafePressureBank
from softarm.harvest.actuator import PressureMap
from softarm.harvest.config import HarvestConfig
from softarm.harvest.log import HarvestLog
from softarm.harvest.machine import HarvestMachine
from softarm.harvest.rig import ControlInputs, build_control_stack
from softarm.harvest.vision_loop import CameraVision
from softarm.identified_plant import IdentifiedPlant
from softarm.vision import MarkerCube
from softarm.vision.camera_model import camera_from_config
from softarm.vision.poses import invert

__all__ = ["HardwareRig", "MonotonicClock", "build_hardware_rig", "hardware_inputs"]


@dataclass
class HardwareRig:
    """The machine and the devices it runs on; ``close()`` vents and releases them."""

    machine: HarvestMachine
    devices: ExitStack

    def close(self) -> None:
        """Vent the arm and release every device."""
        self.devices.close()


def build_hardware_rig(
    config: Config,
    harvest: HarvestConfig | None = None,
    log: HarvestLog | None = None,
    identified: IdentifiedPlant | None = None,
    calibration: Calibration | None = None,
    canes: Sequence[PolynomialCurve] = (),
) -> HardwareRig:
    """Open every device of ``config`` and wire the machine, tuned by ``harvest`` (default:
    the config's ``[harvest]``), on the control stack the simulator uses
    (:func:`~softarm.harvest.rig.build_control_stack`). With the ``identified`` plant
    (``[plant_model]``) the actuator predicts the regulators' lag, with their lead, and
    the loop corrects the motion still in flight (docs/control.md); without it the
    resolver's gain is bounded for the slowest plant (the defaults' 20 periods). The
    ``calibration`` (``--model``) replaces the configured arm and pressure map; the
    ``canes`` (none unless given) are avoided by planner, resolver and way check.

    Raises:
        HardwareUnavailableError: a device (or its driver) is absent.
        ConfigError: the calibration needed by the vision loop is missing.
    """
    cfg = harvest or config.harvest
    cal = config.calibration
    if cal.T_C1_base is None or cal.T_C2_EE is None:
        raise ConfigError("calibration.T_C1_base and calibration.T_C2_EE must be set to harvest")
    inputs = hardware_inputs(config, identified, calibration)
    with ExitStack() as stack:
        bank = _pressure_bank(config, stack)
        s = config.serial
        link = ArduinoLink(
            s.port, s.baud, s.timeout_s, s.retries, startup_delay_s=s.startup_delay_s
        )
        stack.callback(link.close)
        vision = _vision(config, cfg, stack)
        gripper = ArduinoGripper(link)
        clock = MonotonicClock()
        control = build_control_stack(cfg, inputs, canes, bank, clock.now)
        machine = HarvestMachine(
            clock, vision, control.controller, control.actuator, gripper,
            ArduinoRipenessSensor(link), inputs.model.n_actuators, cfg, log,
            planner=control.planner,
        )  # fmt: skip
        return HardwareRig(machine, stack.pop_all())
    raise AssertionError("unreachable")  # pragma: no cover  (the with block returns)


def hardware_inputs(
    config: Config,
    identified: IdentifiedPlant | None = None,
    calibration: Calibration | None = None,
) -> ControlInputs:
    """The control stack's inputs of a hardware ``config``: its arm and channels unless
    a fitted ``calibration`` replaces them, the ``identified`` lag and play, its
    ``[gains]`` (``--gains`` merged in already)."""
    ch = config.channels
    if calibration is None:
        model = SoftArm([Section(**vars(sec)) for sec in config.arm.sections])
        pressure_map: PressureMap = ElongationMap(ch.p_max, ch.metres_per_psi)
    else:
        model, pressure_map = calibration.arm, calibration.pressure_map(ch.p_max)
    return ControlInputs(
        model,
        pressure_map,
        lag_s=None if identified is None else identified.lag_s,
        play_m=0.0 if identified is None else np.asarray(identified.play_m),
        gains=dict(config.gains.values),
    )


def _pressure_bank(config: Config, stack: ExitStack) -> SafePressureBank:
    """The DAQ's outputs behind the safety layer, both closed (vented) by ``stack``."""
    ch = config.channels
    daq = NidaqPressureBank(ch.names, VoltageMap(ch.full_scale_psi, *ch.voltage_range))
    stack.callback(daq.close)
    bank = SafePressureBank(daq, ch.p_max, ch.max_rate_psi_per_s, ch.watchdog_timeout_s)
    stack.callback(bank.close)
    return bank


def _vision(config: Config, cfg: HarvestConfig, stack: ExitStack) -> CameraVision:
    """Both cameras, opened and closed by ``stack``, and the vision loop on them."""
    cal = config.calibration
    model1, model2 = camera_from_config(cal.c1, "c1"), camera_from_config(cal.c2, "c2")
    cam1, cam2 = OpenCVCamera(cal.c1.source), OpenCVCamera(cal.c2.source)
    stack.callback(cam1.close)
    stack.callback(cam2.close)
    return CameraVision(
        lambda t: cam1.read(), lambda t: cam2.read(), model1, model2,
        invert(np.array(cal.T_C1_base)), invert(np.array(cal.T_C2_EE)),
        np.array(cal.T_EE_cube), MarkerCube.standard(), cal.berry_tag, cfg.grasp_offset,
    )  # fmt: skip
