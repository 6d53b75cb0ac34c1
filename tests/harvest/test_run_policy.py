"""The one run policy of both rigs (``softarm.harvest.runs.policy``): in order, a berry lost
from view once more after the others, a stopping fault ends the run, the run's end
logged the same way, one exit-status rule."""

from __future__ import annotations

from typing import Any

from softarm.harvest.machine.interfaces import BerryTarget
from softarm.harvest.machine.states import FaultReason, HarvestState
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.runs.policy import exit_status, finish_run, run_targets

LOST, SAFETY = FaultReason.MARKER_LOST, FaultReason.SAFETY_STOP


class _Log:
    def __init__(self) -> None:
        self.events: list[tuple[str, dict[str, Any]]] = []

    def event(self, kind: str, **fields: object) -> None:
        self.events.append((kind, fields))


def _run(faults: dict[int, list[FaultReason | None]]) -> tuple[list[int], HarvestReport, _Log]:
    order: list[int] = []

    def run_berry(target: BerryTarget) -> BerryResult:
        order.append(target.tag_id)
        fault = faults[target.tag_id].pop(0) if faults.get(target.tag_id) else None
        state = HarvestState.FAULT if fault is not None else HarvestState.DONE
        return BerryResult(target.tag_id, harvested=fault is None, final_state=state, fault=fault)

    log = _Log()
    report = run_targets(run_berry, [BerryTarget(t) for t in (10, 11, 12)], log)
    return order, report, log


def test_a_berry_lost_from_view_is_tried_once_more_after_the_others() -> None:
    order, report, log = _run({10: [LOST]})
    assert order == [10, 11, 12, 10]
    assert [b.tag_id for b in report.berries] == [10, 11, 12]  # each one's last attempt
    assert all(b.harvested for b in report.berries)
    assert [k for k, _ in log.events] == ["run_done"]
    assert exit_status(report, outside_tolerance=False) == 0


def test_lost_twice_is_not_tried_a_third_time() -> None:
    order, report, _ = _run({11: [LOST, LOST]})
    assert order == [10, 11, 12, 11]
    assert report.berries[1].fault is LOST
    assert exit_status(report, outside_tolerance=False) == 1


def test_a_stopping_fault_ends_the_run_and_is_logged() -> None:
    order, report, log = _run({10: [LOST], 11: [SAFETY]})
    assert order == [10, 11]  # no second pass after a stop
    assert report.stopped is SAFETY
    assert report.berries[2].final_state is HarvestState.IDLE  # never tried
    assert log.events[0] == ("run_stopped", {"reason": SAFETY, "remaining": 1})
    assert log.events[1][0] == "run_done"
    assert exit_status(report, outside_tolerance=False) == 1


def test_a_stop_at_the_first_berry_ends_the_run_too() -> None:
    order, report, _ = _run({10: [SAFETY]})
    assert order == [10]
    assert report.stopped is SAFETY


def test_the_exit_status_rule() -> None:
    done = BerryResult(1, harvested=True, final_state=HarvestState.DONE)
    unripe_left = BerryResult(2, final_state=HarvestState.DONE, skipped_unripe=True)
    faulted = BerryResult(3, final_state=HarvestState.FAULT, fault=FaultReason.UNREACHABLE)
    assert exit_status(HarvestReport([done, unripe_left]), outside_tolerance=False) == 0
    assert exit_status(HarvestReport([done]), outside_tolerance=True) == 1
    assert exit_status(HarvestReport([done, faulted]), outside_tolerance=False) == 1


def test_a_map_run_is_finished_the_same_way() -> None:
    """The markerless loop's results (attempts only) get the same stop and records."""
    log = _Log()
    stopped = BerryResult(4, final_state=HarvestState.FAULT, fault=SAFETY)
    report = finish_run(
        HarvestReport([BerryResult(3, final_state=HarvestState.DONE), stopped]), log
    )
    assert report.stopped is SAFETY
    assert [k for k, _ in log.events] == ["run_stopped", "run_done"]
