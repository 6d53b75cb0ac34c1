"""The simulated plant's keys for ``[sweep.plant]``: the same keys, types and ranges as a
``--plant`` file's ``[plant]`` table (:mod:`softarm.sim.plant_file` owns them)."""

from __future__ import annotations

from typing import Any

from softarm.sim.arm import PlantConfig
from softarm.sim.plant_file import PLANT_KEYS, plant_from_mapping, validate_plant_value

__all__ = ["PLANT_KEYS", "column_value", "plant_config", "validate_plant_value"]


def plant_config(point: dict[str, Any]) -> PlantConfig:
    """The plant of one sweep point: the defaults with ``point``'s keys replaced."""
    return plant_from_mapping(point, where="sweep.plant")


def column_value(value: Any) -> Any:
    """A plant value as a table cell: numbers stay numbers; a model name or a gravity
    vector becomes its text."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    if isinstance(value, tuple | list):
        return str(list(value))
    return str(value)
