"""IV-D: simultaneous position and orientation (X and Z) control at 7 poses spread
along +Y, eq. (20) with and without joint-limit avoidance (γ₅ = 0), and the
conventional full-Jacobian resolved rate of eq. (7) for reference."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from softarm._core import Gains, Resolver
from softarm.experiments.common import Trace
from softarm.experiments.output import mean_std, plot_comparison, write_csv, write_json
from softarm.experiments.runner import Controller, bush_cases, start


def _key(name: str) -> str:
    """A controller's name as a CSV column prefix and a summary key."""
    return name.replace(" ", "_")


def run(
    out: Path, seed: int = 0, quick: bool = False, gains: Gains | None = None
) -> dict[str, Any]:
    """Runs the experiment, writes ``hybrid.{csv,json,png}``; returns the summary."""
    s = start(out, seed, 3, gains)
    count, duration = (3, 20.0) if quick else (7, 40.0)
    model = s.plant.model
    controllers = [
        Controller("with limits", Resolver(model, "hybrid", s.gains)),
        Controller("without limits", Resolver(model, "hybrid", s.gains.replace(hybrid_gamma=0.0))),
        Controller("conventional", Resolver(model, "conventional", s.gains), constrained=False),
    ]
    cases = [(s.plant.pose_at_pressure(p), q0) for p, q0 in bush_cases(s.plant, s.rng, count)]
    # Per pose, every controller from the same start (the order of the runs on the plant).
    runs: list[dict[str, Trace]] = [
        {c.name: c.run(s.plant, target, q0, duration) for c in controllers} for target, q0 in cases
    ]
    rows = []
    for i, ((target, _), traces) in enumerate(zip(cases, runs, strict=True)):
        row: list[Any] = [i, *np.round(target[:3, 3], 5)]
        for c in controllers:
            ep, eo = traces[c.name].final()
            row += [ep * 1e3, math.degrees(eo), traces[c.name].infeasible]
        rows.append(row)
    header = ["target", "x", "y", "z"]
    for c in controllers:
        header += [f"{_key(c.name)}_mm", f"{_key(c.name)}_deg", f"{_key(c.name)}_infeasible"]
    write_csv(out / "hybrid.csv", header, rows)
    if runs:
        plot_comparison(
            out / "hybrid.png",
            "IV-D hybrid control, pose 0 (cf. Fig. 9)",
            {k: runs[0][k] for k in ("with limits", "without limits")},
            orientation=True,
        )
    summary: dict[str, Any] = {
        "experiment": "hybrid",
        "poses": count,
        "duration_s": duration,
        "paper": {"mm": {"mean": 0.64, "std": 0.27}, "deg": {"mean": 1.08, "std": 1.5}},
    }
    for c in controllers:
        finals = [traces[c.name].final() for traces in runs]
        summary[_key(c.name)] = {
            "mm": mean_std([ep * 1e3 for ep, _ in finals]),
            "deg": mean_std([math.degrees(eo) for _, eo in finals]),
            "infeasible_commands": sum(traces[c.name].infeasible for traces in runs),
        }
    write_json(out / "hybrid.json", summary)
    return summary
