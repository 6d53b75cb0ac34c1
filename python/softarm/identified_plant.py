"""The identified plant: one value per pressure channel, saved as ``id.json``.

``softarm identify`` writes it; the harvest (``--identified id.json``), the resolver's
lag-aware gains and a ``[plant_model]`` table of the hardware TOML read it back with
:func:`load_identified` / :meth:`IdentifiedPlant.from_mapping`. Every list holds one
value per channel, in actuator order ``[l11, l12, l13, l21, ...]``.

Beside :mod:`softarm.config` (which checks a ``[plant_model]`` table with it), below the
identification that writes it and the harvest that reads it.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softarm.errors import ConfigError
from softarm.files import Range, load_json, number, numbers, write_text

if TYPE_CHECKING:
    from softarm.config import Config

__all__ = ["PER_CHANNEL_KEYS", "IdentifiedPlant", "identified_from_config", "load_identified"]

#: The per-channel lists of ``id.json`` and the range of each value. The ends are what a
#: pneumatic actuator can physically show (the ``[plant]`` file's ranges where it has
#: one): a time constant of 1e16 s is no regulator, and it made the lag model divide by
#: zero (``1 - exp(-T/tau)`` is 0.0 in floating point).
PER_CHANNEL_KEYS: dict[str, Range] = {
    "tau_s": Range(0.0, 10.0, "s", "regulator time constant", lo_open=True),
    "metres_per_psi": Range(
        1e-6, 0.01, "m/psi", "actuator elongation per psi: 0.07 mm to 0.7 m over 70 psi"
    ),
    "hysteresis_psi": Range(0.0, 20.0, "psi", "width of the play band"),
    "dead_time_s": Range(0.0, 10.0, "s", "pure delay from command to pressure"),
}
#: The control period the identification ran at: a real loop runs between 1 kHz and 1 Hz.
CONTROL_PERIOD_S = Range(0.001, 1.0, "s", "control period")


@dataclass(frozen=True)
class IdentifiedPlant:
    """What ``softarm identify`` measured, per channel.

    Attributes:
        tau_s: first-order regulator time constants (s).
        metres_per_psi: actuator elongation per psi (m/psi).
        hysteresis_psi: play band widths (psi).
        dead_time_s: pure delays between command and pressure (s).
        control_period_s: the control period the experiment ran at (s); a lag-aware
            controller wants ``tau_s / control_period_s`` (lag in periods).
        metadata: how it was measured (source, seed, plant, residuals, standard errors).
    """

    tau_s: tuple[float, ...]
    metres_per_psi: tuple[float, ...]
    hysteresis_psi: tuple[float, ...]
    dead_time_s: tuple[float, ...]
    control_period_s: float = 0.05
    metadata: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        _validate(self.to_dict(), "IdentifiedPlant")

    @property
    def n_channels(self) -> int:
        """Number of pressure channels."""
        return len(self.tau_s)

    @property
    def lag_s(self) -> float:
        """The slowest channel's effective lag, time constant plus dead time (s)."""
        return max(t + d for t, d in zip(self.tau_s, self.dead_time_s, strict=True))

    @property
    def play_m(self) -> tuple[float, ...]:
        """The play band widths in elongation (m): ``hysteresis_psi × metres_per_psi``
        per channel (what the lag model's play operator needs)."""
        return tuple(w * k for w, k in zip(self.hysteresis_psi, self.metres_per_psi, strict=True))

    @property
    def lag_periods(self) -> float:
        """:attr:`lag_s` in control periods (what a stability bound on the gain needs)."""
        return self.lag_s / self.control_period_s

    def to_dict(self) -> dict[str, Any]:
        """The ``id.json`` content."""
        return {
            "tau_s": list(self.tau_s),
            "metres_per_psi": list(self.metres_per_psi),
            "hysteresis_psi": list(self.hysteresis_psi),
            "dead_time_s": list(self.dead_time_s),
            "control_period_s": self.control_period_s,
            "metadata": self.metadata,
        }

    def save(self, path: str | Path) -> None:
        """Write ``id.json``."""
        write_text(path, json.dumps(self.to_dict(), indent=2) + "\n", "identified plant")

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], *, where: str = "id.json") -> IdentifiedPlant:
        """From an ``id.json`` object or a ``[plant_model]`` table; ``where`` prefixes the
        key in error messages.

        Raises:
            ConfigError: a list is missing, of the wrong length or holds a bad value; an
                unknown key (one line naming it).
        """
        if not isinstance(data, Mapping):
            raise ConfigError(f"{where}: must be a table/object, got {type(data).__name__}")
        allowed = {*PER_CHANNEL_KEYS, "control_period_s", "metadata"}
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise ConfigError(f"{where}: unknown key {unknown[0]!r}; expected {sorted(allowed)}")
        _validate(data, where)
        meta = data.get("metadata", {})
        if not isinstance(meta, Mapping):
            raise ConfigError(f"{where}.metadata: must be an object, got {meta!r}")
        lists = {k: tuple(float(v) for v in data[k]) for k in PER_CHANNEL_KEYS}
        return cls(
            tau_s=lists["tau_s"],
            metres_per_psi=lists["metres_per_psi"],
            hysteresis_psi=lists["hysteresis_psi"],
            dead_time_s=lists["dead_time_s"],
            control_period_s=float(data.get("control_period_s", 0.05)),
            metadata=dict(meta),
        )


def _validate(data: Mapping[str, Any], where: str) -> None:
    """Every per-channel list present, of one length, each value in its range."""
    n = None
    for key, rng in PER_CHANNEL_KEYS.items():
        if key not in data:
            raise ConfigError(f"{where}: {key} is required (one value per channel)")
        values = numbers(data[key], rng, key, where)
        if n is not None and len(values) != n:
            raise ConfigError(f"{where}: {key}: has {len(values)} values, tau_s has {n}")
        n = len(values)
    number(data.get("control_period_s", 0.05), CONTROL_PERIOD_S, "control_period_s", where)


def load_identified(path: str | Path) -> IdentifiedPlant:
    """Read ``id.json`` (written by ``softarm identify``).

    Raises:
        ConfigError: the file is missing, not JSON, or a value is invalid (one line naming
            the file and the key).
    """
    return IdentifiedPlant.from_mapping(load_json(path, "identified plant"), where=str(path))


def identified_from_config(config: Config, config_path: str | Path) -> IdentifiedPlant | None:
    """The ``[plant_model]`` of a hardware config: its ``file`` (relative to the config
    file) read with :func:`load_identified`, or its inline lists; None without one."""
    pm = config.plant_model
    if pm is None:
        return None
    if pm.file is not None:
        return load_identified(Path(config_path).parent / pm.file)
    data: dict[str, Any] = {k: list(getattr(pm, k) or ()) for k in PER_CHANNEL_KEYS}
    if pm.control_period_s is not None:
        data["control_period_s"] = pm.control_period_s
    return IdentifiedPlant.from_mapping(data, where=f"{config_path}: plant_model")
