"""Gripper, ripeness sensor and pressure monitor on an :class:`ArduinoLink`."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from softarm.errors import HardwareError, OutOfRangeError, ParameterError
from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.serial_protocol import FrameError

__all__ = ["ArduinoGripper", "ArduinoPressureMonitor", "ArduinoRipenessSensor"]

FloatArray = npt.NDArray[np.float64]


def _floats(command: str, values: list[str], count: int) -> list[float]:
    if len(values) != count:
        raise FrameError(f"reply to {command} must carry {count} values, got {values!r}")
    try:
        out = [float(v) for v in values]
    except ValueError as exc:
        raise FrameError(f"reply to {command} is not numeric: {values!r}") from exc
    if not all(math.isfinite(v) for v in out):
        raise HardwareError(f"{command} returned a non-finite value: {values!r}")
    return out


class ArduinoGripper:
    """The tendon gripper's SG90 servo. ``position`` is the closure fraction, mapped
    linearly from ``open_deg`` (0.0) to ``closed_deg`` (1.0)."""

    def __init__(self, link: ArduinoLink, open_deg: float = 10.0, closed_deg: float = 170.0):
        for name, deg in (("open_deg", open_deg), ("closed_deg", closed_deg)):
            if not 0.0 <= deg <= 180.0:
                raise ParameterError(f"{name} must lie in [0, 180] degrees, got {deg!r}")
        if open_deg == closed_deg:
            raise ParameterError(f"open_deg and closed_deg must differ, both are {open_deg!r}")
        self._link = link
        self._open = open_deg
        self._closed = closed_deg

    @property
    def position(self) -> float:
        """Closure fraction read back from the firmware (its commanded servo angle)."""
        (deg,) = _floats("GPOS", self._link.request("GPOS"), 1)
        return (deg - self._open) / (self._closed - self._open)

    def set_position(self, fraction: float) -> None:
        """Move to closure ``fraction`` in [0, 1]."""
        if not (math.isfinite(fraction) and 0.0 <= fraction <= 1.0):
            raise OutOfRangeError(f"fraction must lie in [0, 1], got {fraction!r}")
        deg = self._open + fraction * (self._closed - self._open)
        self._link.request("GRIP", f"{deg:.1f}")

    def open(self) -> None:
        """Open fully."""
        self.set_position(0.0)

    def close(self) -> None:
        """Close fully."""
        self.set_position(1.0)


class ArduinoRipenessSensor:
    """The palm NIR sensor; the firmware returns the ripeness index in [0, 1]."""

    def __init__(self, link: ArduinoLink) -> None:
        self._link = link

    def read(self) -> float:
        """One reading; raises :class:`HardwareError` if it is not a number in [0, 1]."""
        (value,) = _floats("NIR", self._link.request("NIR"), 1)
        if not 0.0 <= value <= 1.0:
            raise HardwareError(f"NIR ripeness index must lie in [0, 1], got {value!r}")
        return value


class ArduinoPressureMonitor:
    """The optional pressure board: ``channels`` readings (psi). Callable, so it can be
    passed as ``NidaqPressureBank(monitor=...)``."""

    def __init__(self, link: ArduinoLink, channels: int = 9) -> None:
        self._link = link
        self._n = channels

    def read_pressures(self) -> FloatArray:
        """The measured pressures (psi), shape ``(channels,)``."""
        return np.array(_floats("PRES", self._link.request("PRES"), self._n))

    def __call__(self) -> FloatArray:
        return self.read_pressures()
