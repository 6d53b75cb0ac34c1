"""The simulated plant's parameters as a TOML ``[plant]`` table (``--plant FILE``).

Every key of :class:`softarm.sim.arm.PlantConfig` has a type and a physically meaningful
range, listed once in :data:`PLANT_KEYS`; :func:`validate_plant_value` checks one value
(the plant dataclass, the plant file and sweep specs all use it), and
:func:`load_plant_file` reads a file into a :class:`~softarm.sim.arm.PlantConfig`. An
unknown key, a wrong type or an out-of-range value is one line naming the key::

    plant.pressure_tau = -1: must be in [0.001, 10] s

Example file::

    [plant]
    model = "pcc"            # constant-curvature plant ("cosserat": a Cosserat rod)
    pressure_tau = 0.3       # s, first-order regulator + hose lag
    hysteresis_psi = 5.0     # psi, width of the play band
    gravity = [0.0, 0.0, -9.81]
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softarm.errors import ConfigError, ParameterError
from softarm.files import load_toml

if TYPE_CHECKING:
    from softarm.sim.arm import PlantConfig

__all__ = [
    "PLANT_KEYS",
    "PLANT_MODELS",
    "PlantKey",
    "load_plant_file",
    "plant_from_mapping",
    "validate_plant_value",
]

#: The plant models the ``model`` key selects: constant-curvature arcs (the controller's
#: own model class, with perturbed geometry) or a Cosserat rod with gravity.
PLANT_MODELS: tuple[str, ...] = ("pcc", "cosserat")


@dataclass(frozen=True)
class PlantKey:
    """One key of the ``[plant]`` table: its kind, closed range and unit, and why."""

    name: str
    kind: str  # "float", "model" or "vector3"
    lo: float = 0.0
    hi: float = 0.0
    unit: str = ""
    doc: str = ""

    def describe(self) -> str:
        """The allowed values, as the error messages and the docs print them."""
        if self.kind == "model":
            return f"one of {list(PLANT_MODELS)}"
        if self.kind == "vector3":
            return f"[gx, gy, gz] with |g| <= {self.hi:g} {self.unit}"
        return f"in [{self.lo:g}, {self.hi:g}]" + (f" {self.unit}" if self.unit else "")


#: Every key of the ``[plant]`` table, in the order of the docs. The ranges are what a
#: pneumatic soft arm can physically show, not what the harvest copes with.
PLANT_KEYS: dict[str, PlantKey] = {
    k.name: k
    for k in (
        PlantKey("model", "model", doc="which physics simulates the arm"),
        PlantKey(
            "pressure_tau", "float", 0.001, 10.0, "s",
            "regulator + hose time constant: 10 ms for a valve at the actuator, seconds "
            "for long thin hoses",
        ),
        PlantKey(
            "hysteresis_psi", "float", 0.0, 20.0, "psi",
            "width of the play band between pressure and elongation (braid friction); "
            "beyond 20 psi the actuator would barely move over its 0-70 psi range",
        ),
        PlantKey(
            "geometry_spread", "float", 0.0, 0.3, "",
            "relative spread (uniform, +-) of radii, rest lengths and plate offsets",
        ),
        PlantKey(
            "gain_spread", "float", 0.0, 0.3, "",
            "relative spread of each actuator's elongation per psi around 1/2100 m/psi",
        ),
        PlantKey(
            "twist_spread", "float", 0.0, 0.5, "rad",
            "spread (uniform, +-) of the twist between sections (0.5 rad is ~29 deg)",
        ),
        PlantKey(
            "position_noise", "float", 0.0, 0.01, "m",
            "tracker noise per axis (a marker tracker is sub-mm; 1 cm is a broken one)",
        ),
        PlantKey(
            "angle_noise", "float", 0.0, 0.1, "rad",
            "tracker rotation noise per axis (0.1 rad is ~5.7 deg)",
        ),
        PlantKey(
            "cutoff", "float", 0.1, 1000.0, "rad/s",
            "tracker low-pass cut-off (the paper's 10 rad/s); 1000 rad/s is no filter at "
            "a 20 Hz control rate",
        ),
        PlantKey(
            "max_psi", "float", 1.0, 100.0, "psi",
            "largest pressure the regulators deliver (the ITV1031 reaches 72.5 psi)",
        ),
        PlantKey(
            "gravity", "vector3", 0.0, 100.0, "m/s^2",
            "gravity in the base frame (used by the Cosserat plant; 100 m/s^2 ~ 10 g)",
        ),
    )
}  # fmt: skip


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def validate_plant_value(key: str, value: Any, *, where: str = "plant") -> Any:
    """Check one ``[plant]`` value; returns it normalised (float, str or a 3-tuple).

    Raises:
        ParameterError: ``key`` is not a plant key, or ``value`` has the wrong type or lies
            outside the key's range; the one-line message names ``where.key``.
    """
    spec = PLANT_KEYS.get(key)
    name = f"{where}.{key}" if where else key
    if spec is None:
        raise ParameterError(f"{name}: unknown plant key; expected one of {list(PLANT_KEYS)}")
    shown = f"{name} = {value!r}"
    if spec.kind == "model":
        if value not in PLANT_MODELS:
            raise ParameterError(f"{shown}: must be {spec.describe()}")
        return str(value)
    if spec.kind == "vector3":
        if (
            not isinstance(value, list | tuple)
            or len(value) != 3
            or not all(_is_number(v) and math.isfinite(v) for v in value)
        ):
            raise ParameterError(f"{shown}: must be a list of 3 finite numbers [gx, gy, gz]")
        g = tuple(float(v) for v in value)
        if math.hypot(*g) > spec.hi:
            raise ParameterError(f"{shown}: must be {spec.describe()}")
        return g
    if not _is_number(value):
        raise ParameterError(f"{shown}: must be a number {spec.describe()}")
    if not (math.isfinite(value) and spec.lo <= value <= spec.hi):
        raise ParameterError(f"{shown}: must be {spec.describe()}")
    return float(value)


def plant_from_mapping(mapping: Mapping[str, Any], *, where: str = "plant") -> PlantConfig:
    """A :class:`~softarm.sim.arm.PlantConfig` from a ``[plant]`` mapping; keys left out
    keep their defaults.

    Raises:
        ParameterError: a key is unknown, or a value is of the wrong type or out of range.
    """
    from softarm.sim.arm import PlantConfig

    if not isinstance(mapping, Mapping):
        raise ParameterError(f"{where}: must be a table of plant keys, got {mapping!r}")
    values = {k: validate_plant_value(k, v, where=where) for k, v in mapping.items()}
    return PlantConfig(**values)


def load_plant_file(path: str | Path) -> PlantConfig:
    """Read the ``[plant]`` table of a TOML file (other tables are left to their owners).

    Raises:
        ConfigError: the file cannot be read, is not TOML, has no ``[plant]`` table, or a
            key is unknown, mistyped or out of range (one line: file, key, value, range).
    """
    path = Path(path)
    data = load_toml(path, "plant file")
    if "plant" not in data:
        raise ConfigError(f"{path}: no [plant] table (keys: {', '.join(PLANT_KEYS)})")
    if not isinstance(data["plant"], dict):
        raise ConfigError(f"{path}: plant must be a table, got {data['plant']!r}")
    try:
        return plant_from_mapping(data["plant"])
    except ParameterError as exc:
        raise ConfigError(f"{path}: {exc}") from exc
