"""The markerless harvest's loop (``harvest_map``): left to right, each ripe berry once,
a berry lost from view tried once more after the others, a stopping fault ends it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.harvest.machine.interfaces import BerryTarget
from softarm.harvest.machine.states import FaultReason
from softarm.harvest.records.report import BerryResult
from softarm.harvest.runs.map_run import harvest_map


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


def test_a_berry_beyond_the_arms_reach_is_never_tried() -> None:
    order: list[int] = []

    def run_berry(target: BerryTarget) -> BerryResult:
        order.append(target.tag_id)
        return BerryResult(target.tag_id, harvested=True)

    bush = _Map([0.1, -0.2, 0.3])
    bush.entries[1].position = np.array([-0.2, 0.9, 0.3])  # along the row, 0.97 m out
    harvest_map(lambda: None, bush, run_berry, 10)  # type: ignore[arg-type]
    assert order == [0, 2]
    order.clear()
    harvest_map(lambda: None, bush, run_berry, 10, reach=1.0)  # type: ignore[arg-type]
    assert order == [1, 0, 2]
