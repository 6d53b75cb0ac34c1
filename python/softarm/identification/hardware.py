"""The identification rig on the real arm: the regulators behind the safety layer (with
the Arduino's pressure board as the pressure monitor: the lag is seen in its readings),
the eye-to-hand camera C1 tracking the marker cube for the end-effector pose, and the
wall clock.

Devices are opened as the harvest opens them (:mod:`softarm.harvest.rigs.hardware.rig`); a missing
one closes and vents what was opened and raises
:class:`~softarm.errors.HardwareUnavailableError` naming it.
"""

from __future__ import annotations

from contextlib import ExitStack

import numpy as np

from softarm.checks import FloatArray as F64
from softarm.config import Config
from softarm.errors import ConfigError
from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.arduino_devices import ArduinoPressureMonitor
from softarm.hardware.camera import OpenCVCamera
from softarm.hardware.clock import MonotonicClock
from softarm.hardware.daq import NidaqPressureBank
from softarm.hardware.latest_frame import newest_frames
from softarm.hardware.pressure_map import VoltageMap
from softarm.hardware.safety import SafePressureBank
from softarm.vision.camera_model import camera_from_config
from softarm.vision.marker_body import marker_body
from softarm.vision.poses import invert
from softarm.vision.two_cameras import CameraVision

__all__ = ["HardwareIdentificationRig"]


class HardwareIdentificationRig:
    """The :class:`~softarm.identification.rig.IdentificationRig` of ``config``.

    Raises:
        ConfigError: C1's extrinsics or intrinsics are missing from the config.
        HardwareUnavailableError: a device or its driver is absent.
    """

    def __init__(self, config: Config, period: float = 0.05) -> None:
        cal, ch = config.calibration, config.channels
        if cal.T_C1_base is None:
            raise ConfigError("calibration.T_C1_base must be set to track the arm")
        model1 = camera_from_config(cal.c1, "c1")
        self.period = period
        self.pose_cutoff: float | None = None  # C1's cube pose is not low-passed
        self.metres_per_psi = ch.metres_per_psi
        self._clock = MonotonicClock()
        with ExitStack() as stack:
            s = config.serial
            link = ArduinoLink(
                s.port, s.baud, s.timeout_s, s.retries, startup_delay_s=s.startup_delay_s
            )
            stack.callback(link.close)
            monitor = ArduinoPressureMonitor(link, len(ch.names))
            daq = NidaqPressureBank(
                ch.names, VoltageMap(ch.full_scale_psi, *ch.voltage_range), monitor=monitor
            )
            stack.callback(daq.close)
            self.bank = SafePressureBank(
                daq, ch.p_max, ch.max_rate_psi_per_s, ch.watchdog_timeout_s
            )
            stack.callback(self.bank.close)
            # Its newest frame: the lag measured is the arm's, not the driver's queue.
            cam = newest_frames(OpenCVCamera(cal.c1.source), cal.c1.source)
            stack.callback(cam.close)
            self.vision = CameraVision(
                lambda t: cam.read(), lambda t: None, model1, model1,
                invert(np.array(cal.T_C1_base)), np.eye(4), np.array(cal.T_EE_cube),
                marker_body(cal.marker_body, cal.marker_length), cal.berry_tag, 0.0,
            )  # fmt: skip
            self._devices = stack.pop_all()

    def now(self) -> float:
        return self._clock.now()

    def advance(self) -> None:
        self._clock.sleep(self.period)

    def pose(self) -> F64 | None:
        return self.vision.track(self.now())

    def close(self) -> None:
        self._devices.close()
