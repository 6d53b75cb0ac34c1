"""IV-B: position control at 35 set-points spread along +Y, the proposed controller
(eq. 13, task 1 over task 3) against conventional resolved rate with the position
Jacobian (eq. 7), counting the conventional controller's infeasible commands."""

from __future__ import annotations

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
from softarm.experiments.output import (
    mean_std,
    plot_comparison,
    plot_final_errors,
    write_csv,
    write_json,
)
from softarm.sim.arm import SimulatedArm


def run(
    out: Path, seed: int = 0, quick: bool = False, gains: Gains | None = None
) -> dict[str, Any]:
    """Runs the experiment, writes ``position.{csv,json,png}`` into ``out``; returns the
    summary."""
    out.mkdir(parents=True, exist_ok=True)
    plant = SimulatedArm(seed=seed)
    rng = np.random.default_rng(seed + 1)
    count, duration = (8, 20.0) if quick else (35, 30.0)
    gains = gains if gains is not None else declared_gains(plant)
    proposed = Resolver(plant.model, "position", gains)
    conventional = Resolver(plant.model, "conventional", gains)
    rows = []
    finals: dict[str, list[float]] = {"proposed": [], "conventional": []}
    infeasible = 0
    example = None
    for i, p in enumerate(bush_pressures(plant, rng, count)):
        target = plant.pose_at_pressure(p)[:3, 3]
        q0 = start_configuration(rng, plant.n)
        a = closed_loop(proposed, plant, target, q0, duration)
        b = closed_loop(conventional, plant, target, q0, duration, constrained=False)
        ea, eb = a.final()[0], b.final()[0]
        finals["proposed"].append(ea * 1e3)
        finals["conventional"].append(eb * 1e3)
        infeasible += b.infeasible
        rows.append(
            [
                i,
                *np.round(target, 5),
                ea * 1e3,
                eb * 1e3,
                a.infeasible,
                b.infeasible,
                a.settle_time(1e-3),
                b.settle_time(1e-3),
            ]
        )
        if example is None or b.infeasible > example[2].infeasible:
            example = (i, a, b)
    write_csv(
        out / "position.csv",
        [
            "target",
            "x",
            "y",
            "z",
            "proposed_mm",
            "conventional_mm",
            "proposed_infeasible",
            "conventional_infeasible",
            "proposed_settle_1mm_s",
            "conventional_settle_1mm_s",
        ],
        rows,
    )
    if example is not None:
        plot_comparison(
            out / "position.png",
            f"IV-B position control, set-point {example[0]} (cf. Fig. 7)",
            {"proposed (eq. 13)": example[1], "conventional (eq. 7)": example[2]},
        )
    plot_final_errors(
        out / "position_final.png",
        "IV-B final position error (cf. Fig. 6)",
        [str(r[0]) for r in rows],
        finals,
        "mm",
    )
    summary = {
        "experiment": "position",
        "set_points": count,
        "duration_s": duration,
        "proposed_mm": mean_std(finals["proposed"]),
        "conventional_mm": mean_std(finals["conventional"]),
        "conventional_infeasible_commands": infeasible,
        "conventional_steps": count * round(duration / 0.05),
        "proposed_infeasible_commands": int(sum(r[6] for r in rows)),
        "conventional_set_points_with_infeasible": int(sum(1 for r in rows if r[7] > 0)),
        "paper_mm": {"mean": 0.84, "std": 0.38},
    }
    write_json(out / "position.json", summary)
    return summary
