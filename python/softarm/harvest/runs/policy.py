"""The one run policy of a harvest, the same for the simulator and the arm: which berries
are tried again, what the run's log records at its end, and the exit status.

* A berry lost from view (MARKER_LOST: the cube or the berry out of sight too long) is
  tried once more after the others: from another start the cameras may keep it (a berry
  tag can hide behind another berry until that one is picked). The markerless loop
  (:func:`~softarm.harvest.runs.map_run.harvest_map`) follows the same rule.
* A fault in FAULTS_THAT_STOP ends the run: ``run_stopped`` is logged with the reason
  and the berries left, then ``run_done`` with the success rate, on every run.
* The exit status (:func:`exit_status`): 0 when the run was not stopped and every berry
  tried ended DONE within the grasp tolerance (an unripe berry left on the bush ends
  DONE), else 1.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from softarm.harvest.machine.interfaces import BerryTarget
from softarm.harvest.machine.states import FAULTS_THAT_STOP, FaultReason, HarvestState
from softarm.harvest.records.report import BerryResult, HarvestReport

__all__ = ["RunLog", "exit_status", "finish_run", "run_targets"]


class RunLog(Protocol):
    """The part of the run's log the policy writes to."""

    def event(self, kind: str, **fields: object) -> None: ...


def run_targets(
    run_berry: Callable[[BerryTarget], BerryResult],
    targets: Sequence[BerryTarget],
    log: RunLog,
    on_berry: Callable[[int, BerryResult], None] | None = None,
) -> HarvestReport:
    """Each of ``targets`` in order, those lost from view once more after the others;
    ``on_berry(i, result)`` after each attempt at target ``i``. The report keeps each
    target's last attempt, in the targets' order (an untried one: not attempted)."""
    report = HarvestReport()
    results: dict[int, BerryResult] = {}
    second = _attempt(run_berry, targets, range(len(targets)), results, on_berry)
    if _stopping(results) is None:
        _attempt(run_berry, targets, second, results, on_berry)
    report.berries = [results.get(i, BerryResult(t.tag_id)) for i, t in enumerate(targets)]
    return finish_run(report, log)


def _attempt(
    run_berry: Callable[[BerryTarget], BerryResult],
    targets: Sequence[BerryTarget],
    order: Sequence[int],
    results: dict[int, BerryResult],
    on_berry: Callable[[int, BerryResult], None] | None,
) -> list[int]:
    """Try the targets at ``order``; the indices lost from view, until a stopping fault."""
    lost: list[int] = []
    for i in order:
        results[i] = run_berry(targets[i])
        if on_berry is not None:
            on_berry(i, results[i])
        if results[i].fault in FAULTS_THAT_STOP:
            break
        if results[i].fault is FaultReason.MARKER_LOST:
            lost.append(i)
    return lost


def _stopping(results: dict[int, BerryResult]) -> int | None:
    """The index whose result stopped the run, if one did."""
    return next((i for i, r in results.items() if r.fault in FAULTS_THAT_STOP), None)


def finish_run(report: HarvestReport, log: RunLog) -> HarvestReport:
    """Log the run's end as every run does (``run_stopped`` when a fault stopped it, then
    ``run_done``) and return ``report``, its ``stopped`` set from its berries (a fault in
    FAULTS_THAT_STOP ends every run at once, so any such fault is the stop)."""
    stops = [b.fault for b in report.berries if b.fault in FAULTS_THAT_STOP]
    report.stopped = stops[0] if stops else None
    if report.stopped is not None:
        left = sum(1 for b in report.berries if b.final_state is HarvestState.IDLE)
        log.event("run_stopped", reason=report.stopped, remaining=left)
    log.event("run_done", success_rate=report.success_rate)
    return report


def exit_status(report: HarvestReport, outside_tolerance: bool) -> int:
    """0 when ``report``'s run was not stopped and each of its berries ended DONE, none
    ``outside_tolerance``; else 1 (a stop by a signal is 130/143, set by the command)."""
    done = all(b.final_state is HarvestState.DONE for b in report.berries)
    return 0 if report.stopped is None and done and not outside_tolerance else 1
