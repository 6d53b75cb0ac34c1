"""Hardware drivers of the soft harvesting arm, behind small protocols.

Nothing here imports a vendor driver at import time: ``nidaqmx`` and ``cv2`` are imported
when a device is opened, and a missing one raises
:class:`~softarm.errors.HardwareUnavailableError` naming the package to install.
Every pressure backend should be used through :class:`SafePressureBank`.
"""

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
