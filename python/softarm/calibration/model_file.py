"""Reading ``model.toml`` (:meth:`Calibration.load`): its structure, then every value
against a declared range.

Each table must be a table and each value a number of the right kind inside its range,
or the load is one :class:`~softarm.errors.ConfigError` line naming the file and the key.
The ranges hold every model the fit can produce (its parameters move at most ±50 % from
the nominal arm, ±π/4 rad in twist) with a margin, and nothing a controller cannot use:
an actuator offset of 1e300 m made every command saturate and left the harvest in IDLE
for ever; a gain of 1e-300 turns each elongation into an infinite command.
"""

from __future__ import annotations

import math
from dataclasses import fields
from typing import Any

import numpy as np

from softarm._core import Section, SoftArm
from softarm.calibration.metrics import PoseErrorStats
from softarm.errors import ConfigError, SoftarmError
from softarm.files import Range, integer, number, numbers, shown

__all__ = ["FORMAT", "GAIN", "OFFSET", "SECTION_KEYS", "model_fields"]

FORMAT = 1

#: The keys of one ``[[arm.sections]]`` table and their ranges (m, rad): a soft arm's
#: section is centimetres wide and tens of centimetres long; a twist past a full turn
#: either way is the same section written twice.
SECTION_KEYS: dict[str, Range] = {
    "radius": Range(0.0, 1.0, "m", lo_open=True),
    "rest_length": Range(0.0, 10.0, "m", lo_open=True),
    "lower": Range(-1.0, 1.0, "m"),
    "upper": Range(-1.0, 1.0, "m"),
    "offset": Range(0.0, 1.0, "m"),
    "twist": Range(-math.tau, math.tau, "rad"),
}
#: True elongation / commanded elongation: the fit keeps it in [0.5, 1.5].
GAIN = Range(0.25, 4.0, "", "true over commanded elongation; the fit keeps it in [0.5, 1.5]")
#: Elongation offset per actuator: the fit's bias keeps it within ±0.071 m.
OFFSET = Range(-0.1, 0.1, "m", "elongation offset; three times an actuator's stroke")
#: Residual statistics of ``[fit]``.
FIT_MM = Range(0.0, 1e6, "mm")
FIT_DEG = Range(0.0, 180.0, "deg")
SAMPLES = Range(1.0, 1e9, "poses")
#: Fitted deviations from the nominal arm (relative, or rad for twists): within ±0.5.
PARAMETER = Range(-1e3, 1e3)


def _table(parent: dict[str, Any], key: str, source: str, where: str = "") -> dict[str, Any]:
    value = parent.get(key, {})
    if not isinstance(value, dict):
        name = f"{where}.{key}" if where else key
        raise ConfigError(f"{source}: {name} = {shown(value)}: must be a table")
    return value


def _section(s: Any, key: str, source: str) -> Section:
    if not isinstance(s, dict) or set(s) != set(SECTION_KEYS):
        raise ConfigError(f"{source}: {key}: expected exactly the keys {', '.join(SECTION_KEYS)}")
    values = {k: number(s[k], rng, f"{key}.{k}", source) for k, rng in SECTION_KEYS.items()}
    try:
        return Section(**values)
    except SoftarmError as exc:
        raise ConfigError(f"{source}: {key}: {exc}") from None


def _arm(data: dict[str, Any], source: str) -> SoftArm:
    raw = _table(data, "arm", source).get("sections")
    if not isinstance(raw, list) or not raw:
        raise ConfigError(f"{source}: arm.sections: must be a non-empty array of tables")
    sections = [_section(s, f"arm.sections[{i}]", source) for i, s in enumerate(raw)]
    try:
        return SoftArm(sections)
    except SoftarmError as exc:
        raise ConfigError(f"{source}: arm.sections: {exc}") from None


def _fit(data: dict[str, Any], source: str) -> PoseErrorStats:
    table = _table(data, "fit", source)
    names = [f.name for f in fields(PoseErrorStats)]
    if set(table) != set(names):
        raise ConfigError(f"{source}: fit: expected exactly the keys {', '.join(names)}")
    values: dict[str, Any] = {"samples": integer(table["samples"], SAMPLES, "fit.samples", source)}
    for name in names[1:]:
        rng = FIT_DEG if name.endswith("_deg") else FIT_MM
        values[name] = number(table[name], rng, f"fit.{name}", source)
    return PoseErrorStats(**values)


def _converged(data: dict[str, Any], source: str) -> bool:
    value = data.get("converged", True)
    if not isinstance(value, bool):  # "no" is a true string: only a TOML boolean will do
        raise ConfigError(f"{source}: converged = {shown(value)}: must be true or false")
    return value


def model_fields(data: dict[str, Any], source: str) -> dict[str, Any]:
    """The :class:`Calibration` keywords of a parsed ``model.toml``."""
    fmt = data.get("format")
    if isinstance(fmt, bool) or fmt != FORMAT:
        raise ConfigError(f"{source}: format = {shown(fmt)}: expected {FORMAT}")
    arm = _arm(data, source)
    n = arm.n_actuators
    actuators = _table(data, "actuators", source)
    gain = numbers(actuators.get("gain"), GAIN, "actuators.gain", source, n)
    offset = numbers(actuators.get("offset", [0.0] * n), OFFSET, "actuators.offset", source, n)
    parameters = _table(data, "parameters", source)
    return {
        "arm": arm,
        "actuator_gain": np.array(gain),
        "actuator_offset": np.array(offset),
        "fit": _fit(data, source),
        "parameters": {
            str(k): number(v, PARAMETER, f"parameters.{k}", source) for k, v in parameters.items()
        },
        "converged": _converged(data, source),
    }
