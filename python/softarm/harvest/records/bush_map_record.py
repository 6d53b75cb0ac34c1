"""The bush map as the log's ``bush_map`` record holds it."""

from __future__ import annotations

from typing import Any

import numpy as np

from softarm.perception.bush_map import BushMap

__all__ = ["map_record"]


def map_record(bush_map: BushMap) -> dict[str, Any]:
    """The map as the log's ``bush_map`` record holds it (units in
    :data:`softarm.harvest.records.header.UNITS`): each berry's id, position, radius, ripeness
    and sightings; each fitted cane's cubic coefficients and radius."""
    berries = [
        {"id": b.id, "position": np.asarray(b.position), "radius_m": b.radius,
         "ripe": b.ripeness == "ripe", "sightings": b.sightings}
        for b in bush_map.berries
    ]  # fmt: skip
    canes = [{"coeffs": np.asarray(c.coeffs), "radius_m": c.radius} for c in bush_map.canes]
    return {"berries": berries, "canes": canes}
