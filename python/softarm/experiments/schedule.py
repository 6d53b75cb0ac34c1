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
from softarm.experiments.common import (
    bush_pressures,
    closed_loop,
    declared_gains,
    start_configuration,
)
from softarm.experiments.output import write_csv, write_json
from softarm.sim.arm import SimulatedArm


def run(
    out: Path, seed: int = 0, quick: bool = False, gains: Gains | None = None
) -> dict[str, Any]:
    """Runs the comparison, writes ``schedule.{csv,json}``; returns the summary."""
    out.mkdir(parents=True, exist_ok=True)
    count, duration, plants = (3, 20.0, 1) if quick else (10, 30.0, 3)
    rows = []
    summary: dict[str, Any] = {
        "experiment": "schedule",
        "targets": count * plants,
        "plants": plants,
        "duration_s": duration,
    }
    # Several plants (seeds), the same targets and starts for both schedules.
    cases = []
    for k in range(plants):
        plant = SimulatedArm(seed=seed + k)
        rng = np.random.default_rng(seed + k + 4)
        for p in bush_pressures(plant, rng, count):
            cases.append((plant, p, start_configuration(rng, plant.n)))
    model = cases[0][0].model
    base = gains if gains is not None else declared_gains(cases[0][0])
    for mode in ("position", "hybrid"):
        for schedule in ("step", "smooth"):
            res = Resolver(model, mode, base.replace(schedule=schedule))
            switch = base.position_switch if mode == "position" else base.hybrid_switch
            finals, settles, jumps, sats = [], [], [], []
            for plant, p, q0 in cases:
                pose = plant.pose_at_pressure(p)
                target = pose[:3, 3] if mode == "position" else pose
                tr = closed_loop(res, plant, target, q0, duration)
                cmd = np.asarray(tr.command_psi)
                e = np.asarray(tr.position_error)
                inside = np.nonzero(e < switch)[0]
                k0 = int(inside[0]) if len(inside) else len(e) - 1
                jump = float(np.abs(np.diff(cmd[k0:], axis=0)).max()) if k0 < len(e) - 1 else 0.0
                finals.append(tr.final()[0] * 1e3)
                settles.append(tr.settle_time(1e-3))
                jumps.append(jump)
                sats.append(tr.saturated)
            key = f"{mode}_{schedule}"
            finite = [s for s in settles if math.isfinite(s)]
            summary[key] = {
                "final_mm_mean": float(np.mean(finals)),
                "final_mm_max": float(np.max(finals)),
                "settle_1mm_s_median": float(np.median(finite)) if finite else math.inf,
                "not_settled": len(settles) - len(finite),
                "max_jump_psi_after_switch": float(np.max(jumps)),
                "saturated_steps": int(np.sum(sats)),
            }
            rows.append([key, *summary[key].values()])
    write_csv(
        out / "schedule.csv",
        ["run", *next(iter(v for k, v in summary.items() if isinstance(v, dict))).keys()],
        rows,
    )
    write_json(out / "schedule.json", summary)
    return summary
