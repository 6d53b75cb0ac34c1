"""Structural interfaces of the hardware: what the harvest loop talks to.

Every backend (NI-DAQmx, Arduino serial, OpenCV, simulated) satisfies one of these
``typing.Protocol`` classes; the safety layer and the harvest loop depend only on them.
Pressures here are gauge pressures in psi: they are the hardware boundary (see
:mod:`softarm.hardware.pressure_map` for the maps to metres and volts).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray

__all__ = ["Camera", "Gripper", "PressureBank", "RipenessSensor"]


@runtime_checkable
class PressureBank(Protocol):
    """A bank of proportional pressure regulators, one per actuator, in actuator order
    q = [l11, l12, l13, l21, ...]."""

    @property
    def channels(self) -> int:
        """Number of pressure channels (9 for the three-section arm)."""
        ...

    @property
    def max_pressure(self) -> float:
        """The highest pressure (psi) this backend can physically produce."""
        ...

    def set_pressures(self, psi: FloatArray) -> None:
        """Command every channel at once; ``psi`` has shape ``(channels,)``."""
        ...

    def vent(self) -> None:
        """Command 0 psi on every channel (exhaust to atmosphere)."""
        ...

    def read_pressures(self) -> FloatArray:
        """The pressures (psi), shape ``(channels,)``: measured when the backend can
        measure them, otherwise the last command."""
        ...

    def close(self) -> None:
        """Vent and release the device. Calling it twice is harmless."""
        ...


@runtime_checkable
class Gripper(Protocol):
    """The tendon-driven three-finger gripper."""

    @property
    def position(self) -> float:
        """Closure fraction: 0.0 fully open, 1.0 fully closed."""
        ...

    def open(self) -> None:
        """Open the fingers fully."""
        ...

    def close(self) -> None:
        """Close the fingers fully (grasp)."""
        ...


@runtime_checkable
class RipenessSensor(Protocol):
    """The NIR reflectance ripeness sensor in the gripper palm."""

    def read(self) -> float:
        """Ripeness index in [0, 1] (0 unripe, 1 ripe); raises HardwareError on a fault."""
        ...


@runtime_checkable
class Camera(Protocol):
    """A colour camera (eye-to-hand C1 or eye-in-hand C2)."""

    def read(self) -> npt.NDArray[np.uint8] | None:
        """One BGR frame of shape ``(h, w, 3)``, or ``None`` when a frame was dropped."""
        ...

    def close(self) -> None:
        """Release the device. Calling it twice is harmless."""
        ...
