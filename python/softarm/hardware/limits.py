"""Physically meaningful ranges for every safety setting of the hardware layer.

One table, used by the constructors (:class:`~softarm.hardware.safety.SafePressureBank`,
:class:`~softarm.hardware.arduino.ArduinoLink`, the watchdog thread) and by the
configuration loader, so a value that the config accepts is one the driver accepts.

Why bounds at all: an unbounded timeout or rate is not "very safe" or "very fast", it is
a different failure. ``watchdog_timeout_s = 1e308`` overflows ``threading.Event.wait``
and kills the watchdog thread; ``1e-300`` makes it spin and vent the arm on every call;
``max_rate_psi_per_s = 1e308`` switches the rate limit off (0 → 70 psi in 1 ms);
``timeout_s = 1e308`` overflows pyserial's ``select``. Each range below states why its
ends are where they are (see also docs/hardware.md, "Bounds of the safety settings").

This module imports nothing but :mod:`softarm.errors`, so the configuration loader can
use it without opening any device.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import cast

from softarm.errors import ParameterError

__all__ = [
    "BAUD",
    "FULL_SCALE_PSI",
    "MAX_RATE_PSI_PER_S",
    "RETRIES",
    "SERIAL_TIMEOUT_S",
    "STARTUP_DELAY_S",
    "WATCHDOG_PERIOD_S",
    "WATCHDOG_TIMEOUT_S",
    "Limit",
]


@dataclass(frozen=True)
class Limit:
    """A closed range ``[lo, hi]`` for one setting, its unit and the reason for it.

    ``integer`` settings accept only ``int`` (never ``bool``); the others accept any real
    number. :meth:`check` returns the value as ``float`` (or ``int``).
    """

    name: str
    lo: float
    hi: float
    unit: str
    why: str
    integer: bool = False

    def describe(self) -> str:
        """``must lie in [lo, hi] unit (why)``: the message tail of every range error."""
        unit = f" {self.unit}" if self.unit else ""
        kind = "an integer" if self.integer else "a finite number"
        return f"must be {kind} in [{self.lo:g}, {self.hi:g}]{unit} ({self.why})"

    def contains(self, value: object) -> bool:
        """Whether ``value`` is a number of the right kind inside the range."""
        if isinstance(value, bool):
            return False
        if self.integer:
            if not isinstance(value, numbers.Integral):
                return False
        elif not isinstance(value, numbers.Real):
            return False
        v = float(value)
        return math.isfinite(v) and self.lo <= v <= self.hi

    def check(self, value: object, name: str | None = None) -> float:
        """Return ``value`` (as ``int`` for integer settings, else ``float``) or raise.

        Raises:
            ParameterError: ``value`` is not a number of the right kind, not finite, or
                outside ``[lo, hi]``; the message names the argument and the value.
        """
        if not self.contains(value):
            raise ParameterError(f"{name or self.name} {self.describe()}, got {value!r}")
        number = cast(float, value)  # contains() checked it is a real number
        return int(number) if self.integer else float(number)


WATCHDOG_TIMEOUT_S = Limit(
    "watchdog_timeout_s",
    0.02,
    10.0,
    "s",
    "below 20 ms the watchdog thread would poll every 5 ms and an ordinary scheduling "
    "delay would vent the arm; after 10 s without a command a held pressure is exactly "
    "the runaway the watchdog exists to stop",
)
WATCHDOG_PERIOD_S = Limit(
    "period_s",
    0.001,
    60.0,
    "s",
    "a check period under 1 ms is a busy loop; over 60 s the watchdog is not watching",
)
MAX_RATE_PSI_PER_S = Limit(
    "max_rate_psi_per_s",
    0.1,
    1000.0,
    "psi/s",
    "the regulators themselves slew about 0-72.5 psi in 0.1 s (~725 psi/s), so a limit "
    "above 1000 psi/s never binds; below 0.1 psi/s a 0-70 psi move takes over 10 min",
)
FULL_SCALE_PSI = Limit(
    "full_scale_psi",
    1.0,
    150.0,
    "psi",
    "the highest set-point range of the SMC ITV10x0 series is 0.9 MPa (130.5 psi); "
    "the silicone actuators burst far below 150 psi",
)
SERIAL_TIMEOUT_S = Limit(
    "timeout_s",
    0.01,
    10.0,
    "s",
    "a 100-byte reply takes ~9 ms at 115200 baud, so no reply can arrive sooner; a "
    "device silent for 10 s is gone, and waiting longer stalls the harvest loop",
)
STARTUP_DELAY_S = Limit(
    "startup_delay_s",
    0.0,
    10.0,
    "s",
    "an Arduino resets when the port opens and its bootloader needs 1-2 s; 10 s is "
    "generous for any board",
)
RETRIES = Limit(
    "retries",
    0,
    10,
    "",
    "every command is idempotent, but more than 10 retries of a failing link only "
    "delays the fault report",
    integer=True,
)
BAUD = Limit(
    "baud",
    300,
    4_000_000,
    "baud",
    "the range of the USB-serial bridges on Arduino boards",
    integer=True,
)
