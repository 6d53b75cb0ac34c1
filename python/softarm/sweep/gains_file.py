"""Resolver gains as a TOML file: a ``[gains]`` table of :class:`softarm.Gains` keywords,
written by ``softarm tune`` and read by ``softarm harvest --gains`` (and by
``softarm.Gains(**tomllib.load(f)["gains"])``). The same table is the ``[gains]`` of a
hardware configuration file.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import softarm
from softarm.config import GAIN_KEYS
from softarm.errors import ConfigError
from softarm.files import load_toml, write_text
from softarm.harvest.control.stack import gains_over

__all__ = ["GAIN_KEYS", "gains_from", "load_gains", "write_gains"]


def gains_from(values: Mapping[str, Any]) -> softarm.Gains:
    """``softarm.Gains`` from keywords over the blackberry defaults.

    Raises:
        ConfigError: an unknown key or a value the resolver refuses, named.
    """
    return gains_over(softarm.Gains(), values)


def load_gains(path: str | Path) -> dict[str, Any]:
    """The ``[gains]`` table of a TOML file, validated (see :func:`gains_from`)."""
    p = Path(path)
    data = load_toml(p, "gains file")
    table = data.get("gains")
    if not isinstance(table, dict):
        raise ConfigError(f"{p}: a [gains] table is required")
    try:
        gains_from(table)
    except ConfigError as exc:
        raise ConfigError(f"{p}: [gains] {exc}") from None
    return dict(table)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | float):
        if not math.isfinite(v):
            raise ConfigError(f"cannot write a non-finite gain {v!r}")
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise ConfigError(f"cannot write gain value {v!r}")


def write_gains(path: str | Path, gains: softarm.Gains, header: str = "") -> None:
    """Write every field of ``gains`` as a ``[gains]`` table, after ``header`` comments."""
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    lines += ["[gains]", *(f"{k} = {_toml_value(v)}" for k, v in gains.as_dict().items())]
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    write_text(p, "\n".join(lines) + "\n", "gains file")
