"""The hardware rig: the same state machine on the real devices, from a TOML config.

Devices are opened in the order of the bring-up (pressure outputs behind the safety
layer, the Arduino for gripper and ripeness sensor, both cameras); if one is missing
everything opened so far is vented and closed again and
:class:`~softarm.errors.HardwareUnavailableError` says which device and why.
"""

from __future__ import annotations

from contextlib import ExitStack
from dataclasses import dataclass

import numpy as np

from softarm._core import Gains, Resolver, Section, SoftArm
from softarm.config import Config
from softarm.errors import ConfigError
from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.arduino_devices import ArduinoGripper, ArduinoRipenessSensor
from softarm.hardware.camera import OpenCVCamera
from softarm.hardware.clock import MonotonicClock
from softarm.hardware.daq import NidaqPressureBank
from softarm.hardware.pressure_map import ElongationMap, VoltageMap
from softarm.hardware.safety import SafePressureBank
from softarm.harvest.actuator import SafeActuator
from softarm.harvest.config import HarvestConfig
from softarm.harvest.controller import ResolverController
from softarm.harvest.ik import ModelIK, planning_resolver
from softarm.harvest.log import HarvestLog
from softarm.harvest.machine import HarvestMachine
from softarm.harvest.plant_model import MEASUREMENT_LAG_PERIODS, predicted_loop_alpha
from softarm.harvest.vision_loop import CameraVision
from softarm.identified_plant import IdentifiedPlant
from softarm.vision import MarkerCube
from softarm.vision.camera_model import camera_from_config
from softarm.vision.poses import invert

__all__ = ["HardwareRig", "MonotonicClock", "build_hardware_rig"]


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
) -> HardwareRig:
    """Open every device of ``config`` and wire the machine, tuned by ``harvest`` (default:
    the config's ``[harvest]``). With the ``identified`` plant (``[plant_model]``) the
    actuator predicts the regulators' lag and the loop corrects the motion still in
    flight (docs/control.md); without it the resolver's gain is bounded for the slowest
    plant (the defaults' 20 periods).

    Raises:
        HardwareUnavailableError: a device (or its driver) is absent.
        ConfigError: the calibration needed by the vision loop is missing.
    """
    cfg = harvest or config.harvest
    cal, ch = config.calibration, config.channels
    if cal.T_C1_base is None or cal.T_C2_EE is None:
        raise ConfigError("calibration.T_C1_base and calibration.T_C2_EE must be set to harvest")
    model1, model2 = camera_from_config(cal.c1, "c1"), camera_from_config(cal.c2, "c2")
    arm = SoftArm([Section(**vars(s)) for s in config.arm.sections])
    gains = Gains(**config.gains.values) if config.gains.values else None
    resolver = Resolver(arm, mode="hybrid", gains=gains)
    with ExitStack() as stack:
        daq = NidaqPressureBank(ch.names, VoltageMap(ch.full_scale_psi, *ch.voltage_range))
        stack.callback(daq.close)
        bank = SafePressureBank(daq, ch.p_max, ch.max_rate_psi_per_s, ch.watchdog_timeout_s)
        stack.callback(bank.close)
        s = config.serial
        link = ArduinoLink(
            s.port, s.baud, s.timeout_s, s.retries, startup_delay_s=s.startup_delay_s
        )
        stack.callback(link.close)
        cam1, cam2 = OpenCVCamera(cal.c1.source), OpenCVCamera(cal.c2.source)
        stack.callback(cam1.close)
        stack.callback(cam2.close)
        vision = CameraVision(
            lambda t: cam1.read(), lambda t: cam2.read(), model1, model2,
            invert(np.array(cal.T_C1_base)), invert(np.array(cal.T_C2_EE)),
            np.array(cal.T_EE_cube), MarkerCube.standard(), cal.berry_tag, cfg.grasp_offset,
        )  # fmt: skip
        gripper = ArduinoGripper(link)
        clock = MonotonicClock()
        lag = None if identified is None else (identified.lag_s, cfg.period)
        # A camera frame of measurement lag behind the identified regulators.
        sensor_lag = MEASUREMENT_LAG_PERIODS * cfg.period
        actuator = SafeActuator(
            bank,
            ElongationMap(ch.p_max, ch.metres_per_psi),
            lag=lag,
            now=clock.now,
            sensor_lag_s=sensor_lag,
            play_m=0.0 if identified is None else np.asarray(identified.play_m),
        )
        predicted = None if lag is None else (lambda: actuator.plant_q)
        if identified is not None and "hybrid_alpha" not in config.gains.values:
            # The loop on the berry goes through the lag model: its gain is cut as the
            # identified lag grows (docs/control.md, section 6), unless [gains] sets it.
            alpha = predicted_loop_alpha(identified.lag_s + sensor_lag)
            resolver = Resolver(
                arm, mode="hybrid", gains=(gains or Gains()).replace(hybrid_alpha=alpha)
            )
        # Following a placement plan: the gain bounded by the whole lag, no prediction
        # (docs/control.md, section 6).
        transport = None
        if identified is not None:
            base = gains if gains is not None else Gains()
            transport = Resolver(
                arm, mode="hybrid", gains=base.replace(lag_periods=identified.lag_s / cfg.period)
            )
        controller = ResolverController(resolver, (), predicted, transport)
        machine = HarvestMachine(
            clock, vision, controller, actuator, gripper,
            ArduinoRipenessSensor(link), arm.n_actuators, cfg, log,
            planner=ModelIK(planning_resolver(arm), cfg),
        )  # fmt: skip
        return HardwareRig(machine, stack.pop_all())
    raise AssertionError("unreachable")  # pragma: no cover  (the with block returns)
