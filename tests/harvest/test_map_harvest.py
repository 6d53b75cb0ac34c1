"""The markerless harvest's loop (``harvest_map``): left to right, each ripe berry once,
a berry lost from view tried once more after the others, a stopping fault ends it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.harvest.interfaces import BerryTarget
from softarm.harvest.map_harvest import harvest_map
from softarm.harvest.report import BerryResult
from softarm.harvest.states import FaultReason


@dataclass
class _Entry:
    id: int
    position: np.ndarray


class _Map:
    def __init__(self, xs: list[float]) -> None:
        self.entries = [_Entry(i, np.array([x, 0.3, 0.3])) for i, x in enumerate(xs)]

    def ripe(self) -> list[_Entry]:
        return list(self.entries)


def _run(faults: dict[int, list[FaultReason | None]], stop_on: tuple = ()) -> list[int]:
    order: list[int] = []

    def run_berry(target: BerryTarget) -> BerryResult:
        order.append(target.tag_id)
        fault = faults.get(target.tag_id, [None]).pop(0) if faults.get(target.tag_id) else None
        return BerryResult(target.tag_id, harvested=fault is None, fault=fault)

    harvest_map(lambda: None, _Map([0.1, -0.2, 0.3]), run_berry, 10, stop_on=stop_on)  # type: ignore[arg-type]
    return order


def test_each_ripe_berry_once_left_to_right() -> None:
    assert _run({}) == [1, 0, 2]


def test_a_berry_lost_from_view_is_tried_once_more_after_the_others() -> None:
    lost = FaultReason.MARKER_LOST
    assert _run({1: [lost]}) == [1, 0, 2, 1]
    assert _run({1: [lost, lost]}) == [1, 0, 2, 1]  # once more, not for ever


def test_other_faults_are_not_retried_and_a_stopping_fault_ends_the_run() -> None:
    assert _run({0: [FaultReason.UNREACHABLE]}) == [1, 0, 2]
    assert _run({0: [FaultReason.SAFETY_STOP]}, stop_on=(FaultReason.SAFETY_STOP,)) == [1, 0]


def test_with_nothing_left_place_more_may_add_fruit_and_is_asked_until_it_has_none() -> None:
    # Two waiting fruit: the first view places one (tried next), the second places
    # nothing; then there is none left to look for, and the loop ends.
    bush_map = _Map([0.1])
    placed = [True, False]
    asked: list[int] = []
    order: list[int] = []

    def place_more() -> bool:
        asked.append(len(order))
        if not placed:
            return False
        if placed.pop(0):
            bush_map.entries.append(_Entry(len(bush_map.entries), np.array([0.5, 0.3, 0.3])))
        return True

    def run_berry(target: BerryTarget) -> BerryResult:
        order.append(target.tag_id)
        return BerryResult(target.tag_id, harvested=True)

    harvest_map(lambda: None, bush_map, run_berry, 10, place_more=place_more)  # type: ignore[arg-type]
    assert order == [0, 1]
    assert asked == [1, 2, 2]  # after each berry with none left, until it says no


def test_place_more_takes_a_look_of_the_rounds() -> None:
    # One round: the berry; the views that follow have no look left to be used by.
    calls: list[int] = []
    order: list[int] = []

    def run_berry(target: BerryTarget) -> BerryResult:
        order.append(target.tag_id)
        return BerryResult(target.tag_id, harvested=True)

    harvest_map(
        lambda: None, _Map([0.1]), run_berry, 1, place_more=lambda: bool(calls.append(1)) or True
    )  # type: ignore[arg-type]
    assert order == [0] and calls == []
