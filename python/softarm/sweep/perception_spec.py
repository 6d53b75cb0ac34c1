"""The perception map's specification (``softarm sweep SPEC`` where SPEC has a
``[perception]`` table instead of ``[sweep]``): a grid of the daylight row's conditions
(light × camera effects × look-alikes × fruit density), a few fresh seeds per cell, and
what is measured on each frame.

```toml
[perception]
seeds = [300000, 300001]              # per cell; required
looks = ["sun", "overcast", "backlight", "dusk"]
effects = ["off", "on"]               # the camera model: raw, off (ideal) or on
lookalikes = ["few", "many"]          # softarm.sim.render.row_look.LOOKALIKES
fruit = ["sparse", "dense"]           # softarm.sim.render.row_look.FRUIT_DENSITY
detectors = ["colour", "net", "net+colour"]
berries = 8                           # the bush's own berries (1..64)
unripe_fraction = 0.3
scale = 1.0                           # C1's image and focal length (0.1..1)
shadows = true                        # the sun casts shadows
canes = true                          # fit the canes and score the map
stereo = true                         # locate the ripe berries by stereo
```

Every error is a :class:`~softarm.errors.ConfigError` whose one line names the file and
the key, e.g. ``spec.toml: [perception] looks: 'noon' is not one of sun, overcast, ...``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from softarm.errors import ConfigError
from softarm.files import load_toml

__all__ = [
    "CELL_KEYS",
    "PerceptionSpec",
    "PerceptionTrial",
    "load_perception_spec",
    "parse_perception_spec",
]

#: The grid's axes, in the order a cell is named.
CELL_KEYS = ("look", "effects", "lookalikes", "fruit")
#: What ``effects`` may hold: ``raw``, the frames as rendered (the renderer's linear
#: output, lens distortion only: dark, since nothing exposes them); ``off``, an ideal
#: camera (auto-exposure alone: no noise, blur, vignetting, white balance error, black
#: level or JPEG, the two eyes alike); ``on``, the look's whole camera model.
EFFECTS = ("raw", "off", "on")


@dataclass(frozen=True)
class PerceptionTrial:
    """One task: one cell of the grid on one seed (one bush, one row, one frame pair)."""

    look: str
    effects: str
    lookalikes: str
    fruit: str
    seed: int
    detectors: tuple[str, ...]
    berries: int
    unripe_fraction: float
    scale: float
    shadows: bool
    canes: bool
    stereo: bool

    @property
    def cell(self) -> tuple[str, str, str, str]:
        """(look, effects, lookalikes, fruit)."""
        return (self.look, self.effects, self.lookalikes, self.fruit)

    @property
    def trial_id(self) -> str:
        """A hash of everything that changes the result (``--resume`` keys on it)."""
        blob = json.dumps(dataclasses.asdict(self), sort_keys=True)
        return hashlib.sha1(blob.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class PerceptionSpec:
    """A parsed, validated perception map (see the module docstring)."""

    seeds: tuple[int, ...]
    looks: tuple[str, ...]
    effects: tuple[str, ...]
    lookalikes: tuple[str, ...]
    fruit: tuple[str, ...]
    detectors: tuple[str, ...]
    berries: int = 8
    unripe_fraction: float = 0.3
    scale: float = 1.0
    shadows: bool = True
    canes: bool = True
    stereo: bool = True
    source: str = "<spec>"

    def cells(self) -> list[tuple[str, str, str, str]]:
        """Every (look, effects, lookalikes, fruit), look-major."""
        return list(itertools.product(self.looks, self.effects, self.lookalikes, self.fruit))

    def trials(self) -> list[PerceptionTrial]:
        """Every (cell, seed)."""
        return [
            PerceptionTrial(
                *cell,
                seed,
                self.detectors,
                self.berries,
                self.unripe_fraction,
                self.scale,
                self.shadows,
                self.canes,
                self.stereo,
            )
            for cell in self.cells()
            for seed in self.seeds
        ]


def is_perception_spec(data: Mapping[str, Any]) -> bool:
    """Whether a parsed spec document is a perception map (has ``[perception]``)."""
    return "perception" in data


def load_perception_spec(path: str | Path) -> PerceptionSpec:
    """Read and validate a perception map file.

    Raises:
        ConfigError: missing file, bad TOML, unknown key, empty list, a value not among
            the allowed ones, wrong type or out of range; the line names the key.
    """
    return parse_perception_spec(load_toml(path, "sweep spec"), str(path))


def _choices() -> dict[str, tuple[str, ...]]:
    from softarm.perception.detector.choice import DETECTORS
    from softarm.sim.render.row_look import FAMILIES, FRUIT_DENSITY, LOOKALIKES

    return {
        "looks": FAMILIES,
        "effects": EFFECTS,
        "lookalikes": tuple(LOOKALIKES),
        "fruit": tuple(FRUIT_DENSITY),
        "detectors": DETECTORS,
    }


#: The defaults of the grid's lists: the map of issue 37 (two levels of each knob).
DEFAULT_LISTS = {
    "looks": ("sun", "overcast", "backlight", "dusk"),
    "effects": ("off", "on"),
    "lookalikes": ("few", "many"),
    "fruit": ("sparse", "dense"),
    "detectors": ("colour", "net", "net+colour"),
}


def parse_perception_spec(data: Mapping[str, Any], source: str = "<spec>") -> PerceptionSpec:
    """Validate an already-parsed TOML document (see :func:`load_perception_spec`)."""

    def error(key: str, message: str) -> ConfigError:
        return ConfigError(f"{source}: [perception] {key}: {message}")

    extra = sorted(set(data) - {"perception"})
    if extra:
        raise ConfigError(f"{source}: [{extra[0]}]: unknown table beside [perception]")
    table = data["perception"]
    if not isinstance(table, dict):
        raise ConfigError(f"{source}: [perception]: must be a table, got {table!r}")
    known = {
        "seeds",
        *DEFAULT_LISTS,
        "berries",
        "unripe_fraction",
        "scale",
        "shadows",
        "canes",
        "stereo",
    }
    unknown = sorted(set(table) - known)
    if unknown:
        raise error(unknown[0], f"unknown key (expected one of {', '.join(sorted(known))})")
    seeds = table.get("seeds")
    if not isinstance(seeds, list) or not seeds:
        raise error("seeds", f"must be a non-empty list of integers, got {seeds!r}")
    if not all(_is_int(s) and s >= 0 for s in seeds):
        raise error("seeds", f"must be integers >= 0, got {seeds!r}")
    if len(set(seeds)) != len(seeds):
        raise error("seeds", f"has duplicates: {seeds!r}")
    lists = {k: _names(table, k, allowed, error) for k, allowed in _choices().items()}
    berries = table.get("berries", 8)
    if not _is_int(berries) or not 1 <= berries <= 64:
        raise error("berries", f"must be an integer in 1..64, got {berries!r}")
    unripe = _number(table, "unripe_fraction", 0.3, (0.0, 1.0), error)
    scale = _number(table, "scale", 1.0, (0.1, 1.0), error)
    flags = {k: table.get(k, True) for k in ("shadows", "canes", "stereo")}
    for key, value in flags.items():
        if not isinstance(value, bool):
            raise error(key, f"must be true or false, got {value!r}")
    return PerceptionSpec(
        tuple(seeds),
        lists["looks"],
        lists["effects"],
        lists["lookalikes"],
        lists["fruit"],
        lists["detectors"],
        berries,
        unripe,
        scale,
        flags["shadows"],
        flags["canes"],
        flags["stereo"],
        source,
    )


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _names(
    table: Mapping[str, Any], key: str, allowed: tuple[str, ...], error: Any
) -> tuple[str, ...]:
    """The list ``key`` of names (the default where absent), each one of ``allowed``."""
    values = table.get(key, list(DEFAULT_LISTS[key]))
    if not isinstance(values, list) or not values:
        raise error(key, f"must be a non-empty list, got {values!r}")
    for v in values:
        if v not in allowed:
            raise error(key, f"{v!r} is not one of {', '.join(allowed)}")
    if len(set(values)) != len(values):
        raise error(key, f"has duplicates: {values!r}")
    return tuple(values)


def _number(
    table: Mapping[str, Any], key: str, default: float, bounds: tuple[float, float], error: Any
) -> float:
    """The number ``key`` (``default`` where absent), in [lo, hi]."""
    v = table.get(key, default)
    ok = isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
    if not ok or not bounds[0] <= v <= bounds[1]:
        raise error(key, f"must be a number in [{bounds[0]:g}, {bounds[1]:g}], got {v!r}")
    return float(v)
