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

__all__ = ["GAIN_KEYS", "apply_gains", "gains_from", "load_gains", "write_gains"]


def gains_from(values: Mapping[str, Any]) -> softarm.Gains:
    """``softarm.Gains`` from keywords over the blackberry defaults.

    Raises:
        ConfigError: an unknown key or a value the resolver refuses, named.
    """
    for key in values:
        if key not in GAIN_KEYS:
            raise ConfigError(f"{key}: unknown gain (expected one of {', '.join(GAIN_KEYS)})")
    try:
        return softarm.Gains(**values)
    except (ValueError, TypeError) as exc:
        raise ConfigError(str(exc)) from None


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


def apply_gains(rig: Any, values: Mapping[str, Any]) -> None:
    """Use ``values`` (gain keywords) in the closed-loop resolver of a built simulated rig,
    over the gains it already has (so a rig-level joint-limit gain is kept unless
    ``values`` sets ``hybrid_gamma``). The planner's resolver is left alone."""
    if not values:
        return
    controller = rig.machine.servo.controller
    resolver = getattr(controller, "resolver", None)
    if resolver is None or not hasattr(resolver, "gains"):
        raise ConfigError(
            f"gains: the rig's controller {type(controller).__name__} has no resolver to tune"
        )
    gains_from(values)  # named errors before anything changes
    controller.resolver = softarm.Resolver(
        resolver.arm, resolver.mode, resolver.gains.replace(**values)
    )
