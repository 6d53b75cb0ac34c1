"""The markerless harvest's loop, the same in the rendered bush and on the arm: pick
the bush map's ripe berries one by one, left to right, looking again with C1 each time
the arm is home (a berry the arm or a picked one hid may come into view), until no ripe
berry is left untried. A berry farther from the base than the arm reaches (a row holds
fruit all along it) is never tried. A berry lost from view (MARKER_LOST: the cube or
the berry out of sight too long) is tried once more after the others, as the tag world
does: from another start the cameras may keep it."""

from __future__ import annotations

from collections.abc import Callable, Collection

import numpy as np

from softarm.harvest.machine.interfaces import BerryTarget
from softarm.harvest.machine.states import FaultReason
from softarm.harvest.records.report import BerryResult
from softarm.perception.bush_map import BushMap, MappedBerry
from softarm.perception.cane_metrics import DEFAULT_REACH

__all__ = ["harvest_map"]


def harvest_map(
    look: Callable[[], object],
    bush_map: BushMap,
    run_berry: Callable[[BerryTarget], BerryResult],
    rounds: int,
    on_result: Callable[[MappedBerry, BerryResult], None] | None = None,
    stop_on: Collection[FaultReason] = (),
    on_look: Callable[[], None] | None = None,
    reach: float = DEFAULT_REACH,
) -> list[BerryResult]:
    """Each berry's result, in the order tried: at most ``rounds`` looks (``look``
    merges one C1 view into ``bush_map``), each followed by the leftmost ripe berry not
    tried yet; ``on_look()`` after each look, ``on_result(entry, result)`` after each
    berry; a fault in ``stop_on`` ends it. Berries farther than ``reach`` (m) from the
    base origin are left alone: no pose of the arm grasps them."""
    results: list[BerryResult] = []
    tried: set[int] = set()
    lost: set[int] = set()  # lost from view once: one more try
    for _ in range(rounds):
        look()
        if on_look is not None:
            on_look()
        ripe = [b for b in bush_map.ripe() if np.linalg.norm(b.position) <= reach]
        todo = [b for b in ripe if b.id not in tried] or [b for b in ripe if b.id in lost]
        if not todo:
            break
        entry = min(todo, key=lambda b: b.position[0])  # left to right
        lost.discard(entry.id)
        result = run_berry(BerryTarget(entry.id, f"map berry {entry.id}"))
        if result.fault is FaultReason.MARKER_LOST and entry.id not in tried:
            lost.add(entry.id)
        tried.add(entry.id)
        results.append(result)
        if on_result is not None:
            on_result(entry, result)
        if result.fault in stop_on:
            break
    return results
