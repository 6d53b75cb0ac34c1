"""The harvest rate (issue 40 item 4): berries per hour of simulated time, survey, moves
and way home included, and where that time goes, by stage, read from the run log's
transitions (each ``transition`` record carries the clock ``t`` and the state it left)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from softarm.harvest.machine.states import HarvestState

__all__ = ["STAGES", "rate_line", "rate_record", "state_seconds"]

#: The stages a rate is broken into, and the machine state each one is.
STAGES: dict[str, HarvestState] = {
    "survey": HarvestState.SURVEY,
    "placement": HarvestState.INITIAL_PLACEMENT,
    "fine_positioning": HarvestState.FINE_POSITIONING,
    "grasp": HarvestState.GRASP,
    "home": HarvestState.RETURN_HOME,
}


def state_seconds(records: Iterable[Mapping[str, Any]]) -> dict[str, float]:
    """Seconds of clock time spent in each state (by its value), between consecutive
    ``transition`` records; the time before the first and after the last is not counted."""
    out: dict[str, float] = {}
    last: float | None = None
    for rec in records:
        if rec.get("kind") != "transition":
            continue
        t = float(rec["t"])
        if last is not None:
            state = str(rec["old"])
            out[state] = out.get(state, 0.0) + (t - last)
        last = t
    return out


def rate_record(
    records: Iterable[Mapping[str, Any]], harvested: int, total_s: float
) -> dict[str, Any]:
    """The rate of a run that harvested ``harvested`` berries in ``total_s`` seconds of
    clock time: ``berries_per_hour``, ``s_per_berry`` (None without a harvested berry)
    and ``stage_s``, seconds by stage (:data:`STAGES`) plus ``other``: waits for the
    cameras, faults, and the time outside any transition."""
    states = state_seconds(records)
    stage_s = {name: states.get(state.value, 0.0) for name, state in STAGES.items()}
    stage_s["other"] = max(0.0, total_s - sum(stage_s.values()))
    return {
        "harvested": harvested,
        "total_s": total_s,
        "berries_per_hour": 3600.0 * harvested / total_s if total_s > 0 else 0.0,
        "s_per_berry": total_s / harvested if harvested else None,
        "stage_s": stage_s,
    }


def rate_line(rate: Mapping[str, Any]) -> str:
    """One line for the command: the rate, then each stage's seconds per harvested berry."""
    n = rate["harvested"]
    if not n:
        return f"rate: 0 berries/h ({rate['total_s']:.1f} s simulated, none harvested)"
    stages: Mapping[str, float] = rate["stage_s"]
    parts = ", ".join(f"{k.replace('_', ' ')} {v / n:.2f}" for k, v in stages.items())
    return (
        f"rate: {rate['berries_per_hour']:.0f} berries/h simulated, "
        f"{rate['s_per_berry']:.2f} s per berry ({parts} s)"
    )
