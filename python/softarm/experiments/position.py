"""IV-B: position control at 35 set-points spread along +Y, the proposed controller
(eq. 13, task 1 over task 3) against conventional resolved rate with the position
Jacobian (eq. 7), counting the conventional controller's infeasible commands."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from softarm._core import Gains, Resolver
from softarm.experiments.common import CONTROL_PERIOD
from softarm.experiments.output import mean_std, plot_final_errors, write_csv, write_json
from softarm.experiments.runner import bush_cases, most_infeasible, plot_pair, run_pairs, start

HEADER = [
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
]


def run(
    out: Path, seed: int = 0, quick: bool = False, gains: Gains | None = None
) -> dict[str, Any]:
    """Runs the experiment, writes ``position.{csv,json,png}`` into ``out``; returns the
    summary."""
    s = start(out, seed, 1, gains)
    count, duration = (8, 20.0) if quick else (35, 30.0)
    proposed = Resolver(s.plant.model, "position", s.gains)
    conventional = Resolver(s.plant.model, "conventional", s.gains)
    cases = [
        (s.plant.pose_at_pressure(p)[:3, 3], q0) for p, q0 in bush_cases(s.plant, s.rng, count)
    ]
    pairs = run_pairs(s.plant, proposed, conventional, cases, duration)
    rows = []
    for i, ((target, _), pair) in enumerate(zip(cases, pairs, strict=True)):
        a, b = pair.proposed, pair.conventional
        rows.append(
            [
                i,
                *np.round(target, 5),
                a.final()[0] * 1e3,
                b.final()[0] * 1e3,
                a.infeasible,
                b.infeasible,
                a.settle_time(1e-3),
                b.settle_time(1e-3),
            ]
        )
    finals = {"proposed": [r[4] for r in rows], "conventional": [r[5] for r in rows]}
    write_csv(out / "position.csv", HEADER, rows)
    example = most_infeasible(pairs)
    if example is not None:
        plot_pair(
            out / "position.png",
            f"IV-B position control, set-point {example} (cf. Fig. 7)",
            pairs[example],
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
        "conventional_infeasible_commands": int(sum(r[7] for r in rows)),
        "conventional_steps": count * round(duration / CONTROL_PERIOD),
        "proposed_infeasible_commands": int(sum(r[6] for r in rows)),
        "conventional_set_points_with_infeasible": int(sum(1 for r in rows if r[7] > 0)),
        "paper_mm": {"mean": 0.84, "std": 0.38},
    }
    write_json(out / "position.json", summary)
    return summary
