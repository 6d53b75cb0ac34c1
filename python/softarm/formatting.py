"""Number formatting of command output: floats rounded to what the measurement supports,
so that a report reads ``0.312`` and not ``0.31200000000000006``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

__all__ = ["plural", "rounded"]


def plural(n: int, noun: str) -> str:
    """``1 berry``, ``2 berries``, ``0 seeds``: a count and its noun, singular for one."""
    if n == 1:
        return f"{n} {noun}"
    return f"{n} {noun[:-1]}ies" if noun.endswith("y") else f"{n} {noun}s"


def rounded(value: Any, digits: int = 6) -> Any:
    """A copy of ``value`` (nested dicts, lists, tuples) with every float rounded to
    ``digits`` significant digits; NaN, infinities and everything else unchanged."""
    if isinstance(value, float):
        if value == 0.0 or not math.isfinite(value):
            return value
        return float(f"{value:.{digits}g}")
    if isinstance(value, Mapping):
        return {k: rounded(v, digits) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [rounded(v, digits) for v in value]
    if hasattr(value, "item") and getattr(value, "ndim", None) == 0:  # numpy scalars
        return rounded(value.item(), digits)
    return value
