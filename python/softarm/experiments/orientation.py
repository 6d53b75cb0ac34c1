"""IV-C: orientation control at 15 orientations from 0 to -150° about the base X axis,
the proposed controller (eq. 13, task 2 over task 3) against conventional resolved
rate for orientation (γ₃ = 0, commands unconstrained)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from softarm._core import Gains, Resolver
from softarm.experiments.common import Trace, start_configuration
from softarm.experiments.output import mean_std, plot_final_errors, write_csv, write_json
from softarm.experiments.runner import most_infeasible, plot_pair, run_pairs, start

HEADER = [
    "target",
    "angle_x_deg",
    "proposed_deg",
    "conventional_deg",
    "proposed_infeasible",
    "conventional_infeasible",
    "proposed_first_below_0.57deg_s",
    "conventional_first_below_0.57deg_s",
]


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


def first_below(trace: Trace, angle: float) -> float:
    """The first time (s) the orientation error is below ``angle`` (rad); inf if never.
    (The paper's 0.57°: a hundredth of a radian.)"""
    return next(
        (t for t, e in zip(trace.time, trace.orientation_error, strict=True) if e < angle),
        math.inf,
    )


def run(
    out: Path, seed: int = 0, quick: bool = False, gains: Gains | None = None
) -> dict[str, Any]:
    """Runs the experiment, writes ``orientation.{csv,json,png}``; returns the summary."""
    s = start(out, seed, 2, gains)
    count, duration = (5, 20.0) if quick else (15, 30.0)
    proposed = Resolver(s.plant.model, "orientation", s.gains)
    conventional = Resolver(s.plant.model, "orientation", s.gains.replace(orientation_gamma=0.0))
    home = s.plant.true_arm.forward(np.zeros(s.plant.n))
    angles = np.linspace(0.0, -150.0, count)
    cases = [
        (rot_x(math.radians(deg), home), start_configuration(s.rng, s.plant.n)) for deg in angles
    ]
    pairs = run_pairs(s.plant, proposed, conventional, cases, duration)
    rows = []
    for i, (deg, pair) in enumerate(zip(angles, pairs, strict=True)):
        a, b = pair.proposed, pair.conventional
        settle = [first_below(tr, math.radians(0.57)) for tr in (a, b)]
        ea, eb = math.degrees(a.final()[1]), math.degrees(b.final()[1])
        rows.append([i, round(float(deg), 2), ea, eb, a.infeasible, b.infeasible, *settle])
    finals = {"proposed": [r[2] for r in rows], "conventional": [r[3] for r in rows]}
    write_csv(out / "orientation.csv", HEADER, rows)
    example = most_infeasible(pairs)
    if example is not None:
        plot_pair(
            out / "orientation.png",
            f"IV-C orientation control, target {example} (cf. Fig. 8)",
            pairs[example],
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
