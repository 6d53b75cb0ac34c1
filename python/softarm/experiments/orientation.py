"""IV-C: orientation control at 15 orientations from 0 to -150° about the base X axis,
the proposed controller (eq. 13, task 2 over task 3) against conventional resolved
rate for orientation (γ₃ = 0, commands unconstrained)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from softarm._core import Gains, Resolver
from softarm.experiments.common import closed_loop, declared_gains, start_configuration
from softarm.experiments.output import (
    mean_std,
    plot_comparison,
    plot_final_errors,
    write_csv,
    write_json,
)
from softarm.sim.arm import SimulatedArm


def rot_x(angle: float, home: np.ndarray) -> np.ndarray:
    """The home (straight-arm) orientation rotated by ``angle`` about the base X axis;
    the translation is unused in orientation mode. (The sections' twists of eq. 3 turn
    the straight arm's gripper about z; a constant-curvature arm cannot undo that, so
    "0°" means the straight arm's orientation.)"""
    c, s = math.cos(angle), math.sin(angle)
    t = np.eye(4)
    t[1:3, 1:3] = [[c, -s], [s, c]]
    t[:3, :3] = t[:3, :3] @ home[:3, :3]
    return t


def run(
    out: Path, seed: int = 0, quick: bool = False, gains: Gains | None = None
) -> dict[str, Any]:
    """Runs the experiment, writes ``orientation.{csv,json,png}``; returns the summary."""
    out.mkdir(parents=True, exist_ok=True)
    plant = SimulatedArm(seed=seed)
    rng = np.random.default_rng(seed + 2)
    count, duration = (5, 20.0) if quick else (15, 30.0)
    gains = gains if gains is not None else declared_gains(plant)
    proposed = Resolver(plant.model, "orientation", gains)
    conventional = Resolver(plant.model, "orientation", gains.replace(orientation_gamma=0.0))
    home = plant.true_arm.forward(np.zeros(plant.n))
    rows = []
    finals: dict[str, list[float]] = {"proposed": [], "conventional": []}
    example = None
    for i, deg in enumerate(np.linspace(0.0, -150.0, count)):
        target = rot_x(math.radians(deg), home)
        q0 = start_configuration(rng, plant.n)
        a = closed_loop(proposed, plant, target, q0, duration)
        b = closed_loop(conventional, plant, target, q0, duration, constrained=False)
        ea, eb = math.degrees(a.final()[1]), math.degrees(b.final()[1])
        finals["proposed"].append(ea)
        finals["conventional"].append(eb)
        settle = [
            next(
                (
                    t
                    for t, e in zip(tr.time, tr.orientation_error, strict=True)
                    if e < math.radians(0.57)
                ),
                math.inf,
            )
            for tr in (a, b)
        ]
        rows.append([i, round(float(deg), 2), ea, eb, a.infeasible, b.infeasible, *settle])
        if example is None or b.infeasible > example[2].infeasible:
            example = (i, a, b)
    write_csv(
        out / "orientation.csv",
        [
            "target",
            "angle_x_deg",
            "proposed_deg",
            "conventional_deg",
            "proposed_infeasible",
            "conventional_infeasible",
            "proposed_first_below_0.57deg_s",
            "conventional_first_below_0.57deg_s",
        ],
        rows,
    )
    if example is not None:
        plot_comparison(
            out / "orientation.png",
            f"IV-C orientation control, target {example[0]} (cf. Fig. 8)",
            {"proposed (eq. 13)": example[1], "conventional (eq. 7)": example[2]},
            orientation=True,
        )
    plot_final_errors(
        out / "orientation_final.png",
        "IV-C final orientation error (X, Z)",
        [str(r[1]) for r in rows],
        finals,
        "deg",
    )
    summary = {
        "experiment": "orientation",
        "orientations": count,
        "duration_s": duration,
        "proposed_deg": mean_std(finals["proposed"]),
        "conventional_deg": mean_std(finals["conventional"]),
        "conventional_infeasible_commands": int(sum(r[5] for r in rows)),
        "proposed_infeasible_commands": int(sum(r[4] for r in rows)),
        "proposed_median_time_to_0.57deg_s": float(np.median([r[6] for r in rows])),
        "conventional_median_time_to_0.57deg_s": float(np.median([r[7] for r in rows])),
        "paper_deg": {"mean": 0.65, "std": 0.24},
    }
    write_json(out / "orientation.json", summary)
    return summary
