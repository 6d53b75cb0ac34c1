"""A second physics for the simulated arm: a Cosserat rod with gravity (PyElastica).

PyElastica is the optional extra ``cosserat`` (``pip install 'softarm[cosserat]'``); it
is imported only when a rod is built, and :func:`require_elastica` says how to install it
when it is absent. :class:`~softarm.sim.cosserat.plant.CosseratPlant` is the plant (the
interface of ``softarm.sim.plant.ArmPlant``), :class:`~softarm.sim.cosserat.rod.RodArm`
the rod, :mod:`~softarm.sim.cosserat.params` its masses and stiffness.
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import TYPE_CHECKING, Any

from softarm.errors import MissingDependencyError

if TYPE_CHECKING:  # imported lazily below (PyElastica is optional)
    from softarm.sim.cosserat.plant import CosseratPlant
    from softarm.sim.cosserat.rod import RodArm

__all__ = ["CosseratPlant", "RodArm", "require_elastica"]


def require_elastica() -> ModuleType:
    """The ``elastica`` module (PyElastica), or a clear error saying how to get it."""
    try:
        return importlib.import_module("elastica")
    except ImportError as exc:
        raise MissingDependencyError(
            "the Cosserat-rod plant needs PyElastica, the optional extra 'cosserat': "
            "pip install 'softarm[cosserat]' (or pip install pyelastica)",
            "cosserat",
        ) from exc


def __getattr__(name: str) -> Any:
    if name == "CosseratPlant":
        from softarm.sim.cosserat.plant import CosseratPlant

        return CosseratPlant
    if name == "RodArm":
        from softarm.sim.cosserat.rod import RodArm

        return RodArm
    raise AttributeError(f"module 'softarm.sim.cosserat' has no attribute {name!r}")
