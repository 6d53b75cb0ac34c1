"""Re-export of :class:`softarm.sim.plant.ArmPlant`, the simulated plant, from its old path.

The plant lives in :mod:`softarm.sim.plant` so that :mod:`softarm.sim` (the Cosserat
plant subclasses it) imports nothing from the harvest layer."""

from __future__ import annotations

from softarm.sim.plant import ArmPlant

__all__ = ["ArmPlant"]
