"""The hardware rig's device boundary: what :func:`~softarm.harvest.rigs.hardware.rig.
build_hardware_rig` opens, and nothing else. :class:`DeviceDrivers` opens the real
devices (the DAQ's analog outputs, the Arduino, the cameras, the wall clock); the dry
run (:mod:`softarm.harvest.rigs.replay.devices`) puts recorded frames and readings in their
place, so the rest of the hardware path runs as it does on the arm.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import ExitStack
from typing import Any, Protocol

from softarm.config import Config
from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.arduino_devices import Link
from softarm.hardware.camera import OpenCVCamera
from softarm.hardware.clock import MonotonicClock
from softarm.hardware.daq import NidaqPressureBank
from softarm.hardware.latest_frame import newest_frames
from softarm.hardware.pressure_map import VoltageMap
from softarm.hardware.protocols import PressureBank
from softarm.harvest.machine.interfaces import Clock
from softarm.harvest.rigs.hardware.stereo import open_stereo
from softarm.perception.c1 import Pair
from softarm.perception_config import PerceptionConfig
from softarm.vision.two_cameras import Frame

__all__ = ["DeviceDrivers", "Devices", "Link"]


class Devices(Protocol):
    """Opens each device of a hardware config; ``stack`` closes it again."""

    def clock(self) -> Clock: ...

    def pressure_outputs(self, config: Config, stack: ExitStack) -> PressureBank: ...

    def arduino(self, config: Config, stack: ExitStack) -> Link: ...

    def stereo(self, perception: PerceptionConfig, stack: ExitStack) -> Callable[[], Pair]: ...

    def c1_frames(self, config: Config, stack: ExitStack, stereo_left: Frame | None) -> Frame:
        """C1's frames for the vision loop: the stereo source's left eye
        (``stereo_left``) when there is one, else the C1 camera."""
        ...

    def c2_frames(self, config: Config, stack: ExitStack) -> Frame: ...


class DeviceDrivers:
    """The real devices: NI-DAQmx outputs, the Arduino over serial, OpenCV cameras and
    the monotonic wall clock."""

    def clock(self) -> Clock:
        return MonotonicClock()

    def pressure_outputs(self, config: Config, stack: ExitStack) -> PressureBank:
        ch = config.channels
        daq = NidaqPressureBank(ch.names, VoltageMap(ch.full_scale_psi, *ch.voltage_range))
        stack.callback(daq.close)
        return daq

    def arduino(self, config: Config, stack: ExitStack) -> Link:
        s = config.serial
        link = ArduinoLink(
            s.port, s.baud, s.timeout_s, s.retries, startup_delay_s=s.startup_delay_s
        )
        stack.callback(link.close)
        return link

    def stereo(self, perception: PerceptionConfig, stack: ExitStack) -> Callable[[], Pair]:
        return open_stereo(perception, _opened, stack)

    def c1_frames(self, config: Config, stack: ExitStack, stereo_left: Frame | None) -> Frame:
        if stereo_left is not None:
            return stereo_left
        return _camera(config.calibration.c1.device, stack)

    def c2_frames(self, config: Config, stack: ExitStack) -> Frame:
        return _camera(config.calibration.c2.device, stack)


def _opened(device: Any) -> Any:
    """An OpenCV camera on ``device`` that gives its newest frame, not the oldest its
    driver queued while the loop was not reading (:mod:`softarm.hardware.latest_frame`)."""
    return newest_frames(OpenCVCamera(device), device)


def _camera(device: Any, stack: ExitStack) -> Frame:
    """An OpenCV camera as ``(time) -> image``, closed by ``stack``."""
    cam = _opened(device)
    stack.callback(cam.close)
    return lambda t: cam.read()
