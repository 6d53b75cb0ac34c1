"""Gripper, ripeness sensor and pressure monitor on an :class:`ArduinoLink`.

Every reading is checked against what the device can physically report (a servo angle in
[0, 180]°, a ripeness index in [0, 1], a gauge pressure between slightly below zero and
the supply's maximum); anything else raises :class:`ReadingError`, a
:class:`~softarm.errors.HardwareError` the harvest loop treats as a device fault.
"""

from __future__ import annotations

import math
import re
from typing import Protocol

import numpy as np

from softarm.checks import FloatArray
from softarm.errors import HardwareError, OutOfRangeError, ParameterError
from softarm.hardware.serial_protocol import FrameError

__all__ = [
    "ArduinoGripper",
    "ArduinoPressureMonitor",
    "ArduinoRipenessSensor",
    "Link",
    "ReadingError",
]


#: Plain decimal numbers only: ``float()`` also takes ``" 1"``, ``"1_0"`` or ``"infinity"``.
_NUMBER = re.compile(r"-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?")
#: The firmware reports angles with 0.1° resolution, so a reading may differ from the
#: configured open/closed angle by half of that.
_ANGLE_RESOLUTION_DEG = 0.1
#: Pressure readings: a gauge sensor at rest may read slightly below zero (offset), but
#: not below -1 psi; the regulators' supply is at most 1.0 MPa (145 psi), so no actuator
#: pressure can exceed that.
PRESSURE_READING_RANGE_PSI = (-1.0, 145.0)


class Link(Protocol):
    """What the devices need of the Arduino: :class:`~softarm.hardware.arduino.
    ArduinoLink`'s request/reply (the dry run replays one)."""

    def request(self, command: str, *args: object) -> list[str]: ...

    def close(self) -> None: ...


class ReadingError(HardwareError):
    """A device reported a value it cannot physically have (a sensor or firmware fault)."""


def _floats(command: str, values: list[str], count: int) -> list[float]:
    if len(values) != count:
        raise FrameError(f"reply to {command} must carry {count} values, got {values!r}")
    try:
        out = [float(v) for v in values]
    except ValueError as exc:
        raise FrameError(f"reply to {command} is not numeric: {values!r}") from exc
    if not all(math.isfinite(v) for v in out):
        raise ReadingError(f"{command} returned a non-finite value: {values!r}")
    if not all(_NUMBER.fullmatch(v) for v in values):
        raise FrameError(f"reply to {command} is not numeric (plain decimals): {values!r}")
    return out


def _in_range(command: str, value: float, lo: float, hi: float, unit: str) -> float:
    if not lo <= value <= hi:
        raise ReadingError(f"{command} reading must lie in [{lo:g}, {hi:g}] {unit}, got {value!r}")
    return value


class ArduinoGripper:
    """The tendon gripper's SG90 servo. ``position`` is the closure fraction, mapped
    linearly from ``open_deg`` (0.0) to ``closed_deg`` (1.0)."""

    def __init__(self, link: Link, open_deg: float = 10.0, closed_deg: float = 170.0):
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
        """Closure fraction in [0, 1] read back from the firmware (its commanded angle).

        Raises:
            ReadingError: the angle lies outside the servo's [0, 180]° or outside the
                configured open…closed span (by more than the 0.1° reporting resolution):
                this host never commands such an angle, so the firmware is confused.
        """
        (deg,) = _floats("GPOS", self._link.request("GPOS"), 1)
        _in_range("GPOS", deg, 0.0, 180.0, "deg")
        lo, hi = sorted((self._open, self._closed))
        tol = _ANGLE_RESOLUTION_DEG / 2.0
        _in_range(
            f"GPOS (open {self._open:g}°, closed {self._closed:g}°)", deg, lo - tol, hi + tol, "deg"
        )
        fraction = (deg - self._open) / (self._closed - self._open)
        return min(max(fraction, 0.0), 1.0)  # within the reporting resolution of an end

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

    def __init__(self, link: Link) -> None:
        self._link = link

    def read(self) -> float:
        """One reading; raises :class:`HardwareError` if it is not a number in [0, 1]."""
        (value,) = _floats("NIR", self._link.request("NIR"), 1)
        return _in_range("NIR ripeness index", value, 0.0, 1.0, "")


class ArduinoPressureMonitor:
    """The optional pressure board: ``channels`` readings (psi). Callable, so it can be
    passed as ``NidaqPressureBank(monitor=...)``.

    Args:
        link: the serial link.
        channels: number of readings per ``PRES`` reply (1–64).
        valid_psi: the physically possible readings ``(lo, hi)``; default
            :data:`PRESSURE_READING_RANGE_PSI` (-1 to 145 psi).
    """

    def __init__(
        self,
        link: Link,
        channels: int = 9,
        valid_psi: tuple[float, float] = PRESSURE_READING_RANGE_PSI,
    ) -> None:
        if isinstance(channels, bool) or not isinstance(channels, int) or not 1 <= channels <= 64:
            raise ParameterError(f"channels must be an integer in [1, 64], got {channels!r}")
        lo, hi = valid_psi
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ParameterError(
                f"valid_psi must be finite (lo, hi) with lo < hi, got {valid_psi!r}"
            )
        self._link = link
        self._n = channels
        self._valid = (float(lo), float(hi))

    def read_pressures(self) -> FloatArray:
        """The measured pressures (psi), shape ``(channels,)``.

        Raises:
            ReadingError: a reading outside ``valid_psi`` (e.g. -30 psi, below vacuum).
        """
        values = _floats("PRES", self._link.request("PRES"), self._n)
        lo, hi = self._valid
        for i, v in enumerate(values):
            _in_range(f"PRES channel {i}", v, lo, hi, "psi")
        return np.array(values)

    def __call__(self) -> FloatArray:
        return self.read_pressures()
