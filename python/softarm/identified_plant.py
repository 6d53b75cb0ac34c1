"""The identified plant: one value per pressure channel, saved as ``id.json``.

``softarm identify`` writes it; the harvest (``--identified id.json``), the resolver's
lag-aware gains and a ``[plant_model]`` table of the hardware TOML read it back with
:func:`load_identified` / :meth:`IdentifiedPlant.from_mapping`. Every list holds one
value per channel, in actuator order ``[l11, l12, l13, l21, ...]``.

Beside :mod:`softarm.config` (which checks a ``[plant_model]`` table with it), below the
identification that writes it and the harvest that reads it;
:mod:`softarm.identification.result` re-exports it.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softarm.errors import ConfigError

if TYPE_CHECKING:
    from softarm.config import Config

__all__ = ["PER_CHANNEL_KEYS", "IdentifiedPlant", "identified_from_config", "load_identified"]

#: The per-channel lists of ``id.json`` and the smallest value each may take.
PER_CHANNEL_KEYS: dict[str, tuple[float, str]] = {
    "tau_s": (0.0, "regulator time constant (s), > 0"),
    "metres_per_psi": (0.0, "actuator elongation per psi (m/psi), > 0"),
    "hysteresis_psi": (0.0, "width of the play band (psi), >= 0"),
    "dead_time_s": (0.0, "pure delay from command to pressure (s), >= 0"),
}
_STRICT = {"tau_s", "metres_per_psi"}  # > 0 rather than >= 0


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
        _validate(self.to_dict(), "IdentifiedPlant", ConfigError)

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
        Path(path).write_text(json.dumps(self.to_dict(), indent=2) + "\n", encoding="utf-8")

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
        _validate(data, where, ConfigError)
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


def _number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _validate(data: Mapping[str, Any], where: str, error: type[Exception]) -> None:
    n = None
    for key, (lo, what) in PER_CHANNEL_KEYS.items():
        if key not in data:
            raise error(f"{where}: {key} is required ({what}, one per channel)")
        values = data[key]
        if not isinstance(values, list | tuple) or not values:
            raise error(f"{where}.{key} = {values!r}: must be a non-empty list ({what})")
        if n is not None and len(values) != n:
            raise error(f"{where}.{key}: has {len(values)} values, tau_s has {n}")
        n = len(values)
        for i, v in enumerate(values):
            if not _number(v) or v < lo or (key in _STRICT and v <= lo):
                raise error(f"{where}.{key}[{i}] = {v!r}: must be a finite {what}")
    period = data.get("control_period_s", 0.05)
    if not _number(period) or period <= 0.0:
        raise error(f"{where}.control_period_s = {period!r}: must be a finite number > 0")


def load_identified(path: str | Path) -> IdentifiedPlant:
    """Read ``id.json`` (written by ``softarm identify``).

    Raises:
        ConfigError: the file is missing, not JSON, or a value is invalid (one line naming
            the file and the key).
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"cannot read identified plant {str(path)!r}: {exc}") from exc
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{path}: not valid JSON: {exc}") from exc
    return IdentifiedPlant.from_mapping(data, where=str(path))


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
