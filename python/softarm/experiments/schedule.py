"""Step (eq. 23-25) against smooth gain scheduling of the joint-limit weight, on the
same targets, in position and hybrid control on the simulated arm. Measures the final
error, the time to get (and stay) within 1 mm, the largest jump of the command between
two steps after the error first falls below the switch distance (the step schedule
switches the weight off there), and how often a command was held at a limit."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from softarm._core import Gains, Resolver
from softarm.experiments.common import Trace
from softarm.experiments.output import write_csv, write_json
from softarm.experiments.runner import Controller, bush_cases, start, target_of


def jump_after_switch(trace: Trace, switch: float) -> float:
    """The largest change of one command (psi) between two steps, from the first step
    whose position error is below ``switch`` on (0 if that is the last step): where the
    step schedule cuts the limit term and the smooth one fades it out."""
    cmd = np.asarray(trace.command_psi)
    e = np.asarray(trace.position_error)
    inside = np.nonzero(e < switch)[0]
    k0 = int(inside[0]) if len(inside) else len(e) - 1
    return float(np.abs(np.diff(cmd[k0:], axis=0)).max()) if k0 < len(e) - 1 else 0.0


def summarise(traces: list[Trace], switch: float) -> dict[str, Any]:
    """One schedule's row over all the cases: final error (mm), median time to stay
    within 1 mm of the runs that did, how many did not, the largest jump after the switch
    and the steps held at a limit."""
    finals = [tr.final()[0] * 1e3 for tr in traces]
    settles = [tr.settle_time(1e-3) for tr in traces]
    finite = [s for s in settles if math.isfinite(s)]
    return {
        "final_mm_mean": float(np.mean(finals)),
        "final_mm_max": float(np.max(finals)),
        "settle_1mm_s_median": float(np.median(finite)) if finite else math.inf,
        "not_settled": len(settles) - len(finite),
        "max_jump_psi_after_switch": float(
            np.max([jump_after_switch(tr, switch) for tr in traces])
        ),
        "saturated_steps": int(np.sum([tr.saturated for tr in traces])),
    }


def run(
    out: Path, seed: int = 0, quick: bool = False, gains: Gains | None = None
) -> dict[str, Any]:
    """Runs the comparison, writes ``schedule.{csv,json}``; returns the summary."""
    count, duration, plants = (3, 20.0, 1) if quick else (10, 30.0, 3)
    summary: dict[str, Any] = {
        "experiment": "schedule",
        "targets": count * plants,
        "plants": plants,
        "duration_s": duration,
    }
    # Several plants (seeds), the same targets and starts for both schedules.
    starts = [start(out, seed + k, 4, gains) for k in range(plants)]
    cases = [(s.plant, p, q0) for s in starts for p, q0 in bush_cases(s.plant, s.rng, count)]
    model, base = starts[0].plant.model, starts[0].gains
    rows = []
    for mode in ("position", "hybrid"):
        switch = base.position_switch if mode == "position" else base.hybrid_switch
        for schedule in ("step", "smooth"):
            c = Controller(schedule, Resolver(model, mode, base.replace(schedule=schedule)))
            traces = [
                c.run(plant, target_of(plant.pose_at_pressure(p), mode), q0, duration)
                for plant, p, q0 in cases
            ]
            key = f"{mode}_{schedule}"
            summary[key] = summarise(traces, switch)
            rows.append([key, *summary[key].values()])
    write_csv(out / "schedule.csv", ["run", *summary["position_step"].keys()], rows)
    write_json(out / "schedule.json", summary)
    return summary
