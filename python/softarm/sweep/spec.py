"""The sweep specification: a TOML file with ``[sweep]`` (seeds, berries, rig and controller
settings), ``[sweep.plant]`` (a list of values per plant key), optional ``[sweep.gains]``
(fixed resolver gains) and, for ``softarm tune``, ``[tune]`` (budget and search space).

Every error is a :class:`~softarm.errors.ConfigError` whose one-line message names the file
and the key, e.g. ``spec.toml: [sweep.plant] pressure_tau: empty list``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softarm.errors import ConfigError, SoftarmError
from softarm.files import load_toml

__all__ = [
    "RIG_KEYS",
    "SweepSpec",
    "TrialSpec",
    "TuneRange",
    "TuneSpec",
    "load_spec",
    "parse_spec",
]

#: ``[sweep]`` keys forwarded to :class:`~softarm.harvest.rigs.sim.options.SimRigOptions`, with the
#: type each must have (the rig's and the closed-loop controller's settings).
RIG_KEYS: dict[str, type | tuple[type, ...]] = {
    "scale": float,
    "noise_std": float,
    "unripe_fraction": float,
    "avoid_canes": bool,
    "joint_limit_gain": float,
}


@dataclass(frozen=True)
class TrialSpec:
    """One Ray task: one plant point harvested on one seed's bush.

    ``trial_id`` hashes everything that changes the result (plant, seed, berries, rig
    settings, gains), so ``--resume`` never mistakes a trial of another spec for this one.
    """

    seed: int
    plant: dict[str, Any]
    berries: int
    rig: dict[str, Any]
    gains: dict[str, Any]

    @property
    def trial_id(self) -> str:
        blob = json.dumps(dataclasses.asdict(self), sort_keys=True, default=str)
        return hashlib.sha1(blob.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class TuneRange:
    """A search dimension of ``[tune.space]``: a float range (``log`` for log-uniform)
    or, when ``choices`` is set, a categorical choice."""

    low: float = math.nan
    high: float = math.nan
    log: bool = False
    choices: tuple[Any, ...] | None = None


@dataclass(frozen=True)
class TuneSpec:
    """``[tune]``: number of configurations tried, the searcher's seed and the space."""

    samples: int = 16
    seed: int = 0
    space: dict[str, TuneRange] = field(default_factory=dict)


@dataclass(frozen=True)
class SweepSpec:
    """A parsed, validated sweep specification."""

    seeds: tuple[int, ...]
    berries: int
    plant: dict[str, tuple[Any, ...]]
    rig: dict[str, Any] = field(default_factory=dict)
    gains: dict[str, Any] = field(default_factory=dict)
    tune: TuneSpec = field(default_factory=TuneSpec)
    source: str = "<spec>"

    @property
    def swept_keys(self) -> list[str]:
        """The plant keys that vary, in spec order (one column each in the results)."""
        return list(self.plant)

    def plant_points(self) -> list[dict[str, Any]]:
        """Every combination of the swept plant values (the Cartesian product)."""
        keys = self.swept_keys
        return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(
            *(self.plant[k] for k in keys)
        )]  # fmt: skip

    def trials(self) -> list[TrialSpec]:
        """Every (plant point, seed) pair, plant-major."""
        return [
            TrialSpec(seed, point, self.berries, dict(self.rig), dict(self.gains))
            for point in self.plant_points()
            for seed in self.seeds
        ]

    def with_gains(self, gains: Mapping[str, Any]) -> SweepSpec:
        """A copy whose trials use ``gains`` (over the spec's own ``[sweep.gains]``)."""
        return dataclasses.replace(self, gains={**self.gains, **gains})


def load_spec(path: str | Path) -> SweepSpec:
    """Read and validate a sweep specification file.

    Raises:
        ConfigError: missing file, bad TOML, unknown key, empty list, wrong type or a value
            out of range; the one-line message names the key.
    """
    return parse_spec(load_toml(path, "sweep spec"), str(path))


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


class _Reader:
    """Error helpers bound to the spec's file name."""

    def __init__(self, source: str) -> None:
        self.source = source

    def error(self, where: str, key: str, message: str) -> ConfigError:
        return ConfigError(f"{self.source}: [{where}] {key}: {message}")

    def table(self, parent: Mapping[str, Any], name: str, where: str) -> dict[str, Any]:
        value = parent.get(name, {})
        if not isinstance(value, dict):
            raise self.error(where, name, f"must be a table, got {value!r}")
        return value

    def unknown(self, table: Mapping[str, Any], known: set[str], where: str, hint: str) -> None:
        extra = sorted(set(table) - known)
        if extra:
            raise self.error(where, extra[0], f"unknown key ({hint})")


def parse_spec(data: Mapping[str, Any], source: str = "<spec>") -> SweepSpec:
    """Validate an already-parsed TOML document (see :func:`load_spec`)."""
    r = _Reader(source)
    r.unknown(data, {"sweep", "tune"}, "top level", "expected [sweep] and optional [tune]")
    if "sweep" not in data:
        raise ConfigError(f"{source}: [sweep] table is required but missing")
    sweep = r.table(data, "sweep", "top level")
    known = {"seeds", "berries", "plant", "gains", *RIG_KEYS}
    r.unknown(sweep, known, "sweep", f"expected one of {', '.join(sorted(known))}")

    seeds = sweep.get("seeds")
    if not isinstance(seeds, list) or not seeds:
        raise r.error("sweep", "seeds", f"must be a non-empty list of integers, got {seeds!r}")
    if not all(_is_int(s) and s >= 0 for s in seeds):
        raise r.error("sweep", "seeds", f"must be integers >= 0, got {seeds!r}")
    if len(set(seeds)) != len(seeds):
        raise r.error("sweep", "seeds", f"has duplicates: {seeds!r}")
    berries: Any = sweep.get("berries")
    if not _is_int(berries) or not 1 <= berries <= 64:
        raise r.error("sweep", "berries", f"must be an integer in 1..64, got {berries!r}")

    rig: dict[str, Any] = {}
    for key, kind in RIG_KEYS.items():
        if key not in sweep:
            continue
        v = sweep[key]
        ok = isinstance(v, bool) if kind is bool else _is_number(v)
        if not ok:
            raise r.error("sweep", key, f"must be a {kind.__name__}, got {v!r}")  # type: ignore[union-attr]
        rig[key] = v if kind is bool else float(v)
    _check_rig(rig, r)

    plant = _parse_plant(r.table(sweep, "plant", "sweep"), r)
    gains = _parse_gains(r.table(sweep, "gains", "sweep"), "sweep.gains", r)
    tune = _parse_tune(r.table(data, "tune", "top level"), r)
    return SweepSpec(tuple(seeds), berries, plant, rig, gains, tune, source)


def _check_rig(rig: dict[str, Any], r: _Reader) -> None:
    """The rig's options are checked by building them once (the rig's own validation)."""
    from softarm.harvest.rigs.sim.options import SimRigOptions

    try:
        SimRigOptions(**rig)
    except (SoftarmError, ValueError, TypeError) as exc:
        raise r.error("sweep", next(iter(rig), "?"), str(exc)) from None
    if rig.get("scale", 1.0) <= 0.0 or rig.get("noise_std", 0.0) < 0.0:
        key = "scale" if rig.get("scale", 1.0) <= 0.0 else "noise_std"
        raise r.error("sweep", key, f"out of range, got {rig[key]!r}")
    if not 0.0 <= rig.get("unripe_fraction", 0.0) <= 1.0:
        raise r.error(
            "sweep", "unripe_fraction", f"must be in [0, 1], got {rig['unripe_fraction']!r}"
        )


def _parse_plant(table: dict[str, Any], r: _Reader) -> dict[str, tuple[Any, ...]]:
    from softarm.sweep.plant_keys import PLANT_KEYS, validate_plant_value

    out: dict[str, tuple[Any, ...]] = {}
    for key, values in table.items():
        if key not in PLANT_KEYS:
            expected = ", ".join(PLANT_KEYS)
            raise r.error("sweep.plant", key, f"unknown plant key (expected one of {expected})")
        if not isinstance(values, list):
            raise r.error("sweep.plant", key, f"must be a list of values, got {values!r}")
        if not values:
            raise r.error("sweep.plant", key, "empty list")
        try:
            checked = tuple(validate_plant_value(key, v, where="sweep.plant") for v in values)
        except (SoftarmError, ValueError, TypeError) as exc:
            # The validator's message already names sweep.plant.<key>, the value and range.
            raise ConfigError(f"{r.source}: {exc}") from None
        if len(set(checked)) != len(checked):
            raise r.error("sweep.plant", key, f"has duplicates: {values!r}")
        out[key] = checked
    return out


def _parse_gains(table: dict[str, Any], where: str, r: _Reader) -> dict[str, Any]:
    """Fixed resolver gains: ``softarm.Gains`` keywords, checked by building them."""
    from softarm.sweep.gains_file import gains_from

    try:
        gains_from(table)
    except ConfigError as exc:
        raise ConfigError(f"{r.source}: [{where}] {exc}") from None
    return dict(table)


def _parse_tune(table: dict[str, Any], r: _Reader) -> TuneSpec:
    from softarm.sweep.gains_file import GAIN_KEYS

    r.unknown(table, {"samples", "seed", "space"}, "tune", "expected samples, seed, space")
    samples = table.get("samples", TuneSpec.samples)
    if not _is_int(samples) or samples < 1:
        raise r.error("tune", "samples", f"must be an integer >= 1, got {samples!r}")
    seed = table.get("seed", TuneSpec.seed)
    if not _is_int(seed):
        raise r.error("tune", "seed", f"must be an integer, got {seed!r}")
    space: dict[str, TuneRange] = {}
    for key, v in r.table(table, "space", "tune").items():
        if key not in GAIN_KEYS:
            raise r.error("tune.space", key, "unknown key (expected a softarm.Gains field)")
        space[key] = _parse_range(key, v, r)
    return TuneSpec(samples, seed, space)


def _parse_range(key: str, v: Any, r: _Reader) -> TuneRange:
    """``[lo, hi]`` (uniform), ``{low, high, log}`` or ``{choices = [...]}``."""
    if isinstance(v, list):
        v = {"low": v[0], "high": v[1]} if len(v) == 2 else {"bad": v}
    if not isinstance(v, dict) or not v:
        raise r.error("tune.space", key, f"must be [low, high] or a table, got {v!r}")
    if "choices" in v:
        choices = v["choices"]
        if set(v) != {"choices"} or not isinstance(choices, list) or not choices:
            raise r.error("tune.space", key, f"choices must be a non-empty list, got {v!r}")
        return TuneRange(choices=tuple(choices))
    if not set(v) <= {"low", "high", "log"} or not {"low", "high"} <= set(v):
        raise r.error("tune.space", key, f"must be [low, high] or {{low, high, log}}, got {v!r}")
    lo, hi, log = v["low"], v["high"], v.get("log", False)
    if not (_is_number(lo) and _is_number(hi) and lo < hi and isinstance(log, bool)):
        raise r.error("tune.space", key, f"needs finite numbers low < high, got {v!r}")
    if log and lo <= 0.0:
        raise r.error("tune.space", key, f"a log range needs low > 0, got {v!r}")
    return TuneRange(float(lo), float(hi), log)
