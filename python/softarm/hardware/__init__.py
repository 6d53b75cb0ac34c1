"""Hardware drivers of the soft harvesting arm, behind small protocols.

Nothing here imports a vendor driver at import time: ``nidaqmx`` and ``cv2`` are imported
when a device is opened, and a missing one raises
:class:`~softarm.errors.HardwareUnavailableError` naming the package to install.
Every pressure backend should be used through :class:`SafePressureBank`.

The names below are imported from their submodules on first access, so
``softarm.hardware.limits`` (which the configuration loader uses) costs neither numpy nor
pyserial.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from softarm.hardware.arduino import ArduinoLink
    from softarm.hardware.arduino_devices import (
        ArduinoGripper,
        ArduinoPressureMonitor,
        ArduinoRipenessSensor,
        ReadingError,
    )
    from softarm.hardware.camera import OpenCVCamera
    from softarm.hardware.daq import NidaqPressureBank
    from softarm.hardware.pressure_map import (
        ITV1031_FULL_SCALE_PSI,
        METRES_PER_PSI,
        ElongationMap,
        VoltageMap,
    )
    from softarm.hardware.protocols import Camera, Gripper, PressureBank, RipenessSensor
    from softarm.hardware.safety import CommandResult, SafePressureBank, VentEvent
    from softarm.hardware.serial_protocol import (
        ChecksumError,
        DeviceError,
        DisconnectedError,
        FrameError,
        SerialTimeoutError,
    )
    from softarm.hardware.simulated import (
        Faults,
        IdealPlant,
        PressurePlant,
        SimulatedCamera,
        SimulatedGripper,
        SimulatedPressureBank,
        SimulatedRipenessSensor,
    )

#: Public name → the submodule that defines it.
_WHERE = {
    "ArduinoLink": "arduino",
    **dict.fromkeys(
        ["ArduinoGripper", "ArduinoPressureMonitor", "ArduinoRipenessSensor", "ReadingError"],
        "arduino_devices",
    ),
    "OpenCVCamera": "camera",
    "NidaqPressureBank": "daq",
    **dict.fromkeys(
        ["ITV1031_FULL_SCALE_PSI", "METRES_PER_PSI", "ElongationMap", "VoltageMap"],
        "pressure_map",
    ),
    **dict.fromkeys(["Camera", "Gripper", "PressureBank", "RipenessSensor"], "protocols"),
    **dict.fromkeys(["CommandResult", "SafePressureBank", "VentEvent"], "safety"),
    **dict.fromkeys(
        ["ChecksumError", "DeviceError", "DisconnectedError", "FrameError", "SerialTimeoutError"],
        "serial_protocol",
    ),
    **dict.fromkeys(
        [
            "Faults",
            "IdealPlant",
            "PressurePlant",
            "SimulatedCamera",
            "SimulatedGripper",
            "SimulatedPressureBank",
            "SimulatedRipenessSensor",
        ],
        "simulated",
    ),
}

__all__ = [
    "ITV1031_FULL_SCALE_PSI",
    "METRES_PER_PSI",
    "ArduinoGripper",
    "ArduinoLink",
    "ArduinoPressureMonitor",
    "ArduinoRipenessSensor",
    "Camera",
    "ChecksumError",
    "CommandResult",
    "DeviceError",
    "DisconnectedError",
    "ElongationMap",
    "Faults",
    "FrameError",
    "Gripper",
    "IdealPlant",
    "NidaqPressureBank",
    "OpenCVCamera",
    "PressureBank",
    "PressurePlant",
    "ReadingError",
    "RipenessSensor",
    "SafePressureBank",
    "SerialTimeoutError",
    "SimulatedCamera",
    "SimulatedGripper",
    "SimulatedPressureBank",
    "SimulatedRipenessSensor",
    "VentEvent",
    "VoltageMap",
]


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'softarm.hardware' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"softarm.hardware.{module}"), name)
    globals()[name] = value  # later accesses skip __getattr__
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_WHERE])
