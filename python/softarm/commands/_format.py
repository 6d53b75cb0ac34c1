"""Number formatting of command output: floats rounded to what the measurement supports,
so that a report reads ``0.312`` and not ``0.31200000000000006``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

__all__ = ["rounded"]


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
