"""Declared ranges of the numbers in a file, and the one check every loader makes.

A loader declares each key's :class:`Range` once and calls :func:`number`,
:func:`numbers` or :func:`integer`; the check refuses booleans and strings that look like
numbers, non-finite values, integers too large for a float, and values outside the range,
each as one :class:`~softarm.errors.ConfigError` line naming the file and the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from softarm.errors import ConfigError

__all__ = ["Range", "integer", "number", "numbers", "shown"]

#: Longest excerpt of a bad value in a message: keeps the error one short line when the
#: value is a 400-digit number or a long list.
SHOWN_CHARS = 40


def shown(value: Any) -> str:
    """``repr(value)``, cut to :data:`SHOWN_CHARS` characters."""
    text = repr(value)
    return text if len(text) <= SHOWN_CHARS else text[: SHOWN_CHARS - 3] + "..."


@dataclass(frozen=True)
class Range:
    """The closed range ``[lo, hi]`` of one key (open at ``lo`` when ``lo_open``), its unit
    and why the ends are where they are."""

    lo: float
    hi: float
    unit: str = ""
    why: str = ""
    lo_open: bool = False

    def contains(self, value: float) -> bool:
        above = value > self.lo if self.lo_open else value >= self.lo
        return math.isfinite(value) and above and value <= self.hi

    def describe(self) -> str:
        """``in (lo, hi] unit (why)``: the tail of every range error."""
        bracket = "(" if self.lo_open else "["
        unit = f" {self.unit}" if self.unit else ""
        why = f" ({self.why})" if self.why else ""
        return f"in {bracket}{self.lo:g}, {self.hi:g}]{unit}{why}"


def _real(value: Any) -> float | None:
    """``value`` as a float if it is a real number (not a bool, not a string), else None;
    an integer too large for a float becomes inf, which no range contains."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    try:
        return float(value)
    except OverflowError:
        return math.inf


def number(value: Any, rng: Range, key: str, source: str) -> float:
    """``value`` as a float, or a ConfigError ``source: key = value: must be ...``."""
    x = _real(value)
    if x is None or not rng.contains(x):
        raise ConfigError(
            f"{source}: {key} = {shown(value)}: must be a finite number {rng.describe()}"
        )
    return x


def integer(value: Any, rng: Range, key: str, source: str) -> int:
    """``value`` as an int (a bool or a float is refused), or a ConfigError."""
    x = _real(value)
    if not isinstance(value, int) or x is None or not rng.contains(x):
        raise ConfigError(f"{source}: {key} = {shown(value)}: must be an integer {rng.describe()}")
    return value


def numbers(
    value: Any, rng: Range, key: str, source: str, length: int | None = None
) -> tuple[float, ...]:
    """A non-empty list of numbers each in ``rng`` (exactly ``length`` of them when given);
    the error names the first bad element, ``key[i]``."""
    if not isinstance(value, list | tuple) or not value:
        raise ConfigError(f"{source}: {key} = {shown(value)}: must be a non-empty list")
    if length is not None and len(value) != length:
        raise ConfigError(f"{source}: {key}: must hold {length} values, got {len(value)}")
    return tuple(number(v, rng, f"{key}[{i}]", source) for i, v in enumerate(value))
