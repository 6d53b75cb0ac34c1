"""Identification errors against the simulated plant's truth, over seeds and plants
(the tables of docs/identification.md)::

    python -m softarm.identification.evaluate --seeds 1000-1019 --out out/identify.json

Each (plant, seed) runs ``softarm identify --sim`` (the same code path) and compares the
identified lists with the plant's true values: relative errors for the time constant,
the elongation per psi and the hysteresis, the absolute error for the dead time (the
simulated plant has none).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from softarm.identification.estimate import estimate
from softarm.identification.kinematic import fit_kinematics
from softarm.identification.protocol import Design
from softarm.identification.record import run_experiment
from softarm.identification.rig import SimIdentificationRig
from softarm.sim.arm import PlantConfig

#: The plants of the table: the harvest's default, two slow and hysteretic ones (the
#: closed-loop goals' range), and one twice as far from the nominal geometry.
PLANTS: dict[str, dict[str, Any]] = {
    "default (tau 0.08 s, 1.5 psi, 3 %)": {},
    "tau 0.3 s, 5 psi": {"pressure_tau": 0.3, "hysteresis_psi": 5.0},
    "tau 1.0 s, 5 psi": {"pressure_tau": 1.0, "hysteresis_psi": 5.0},
    "spreads 6 %": {"geometry_spread": 0.06, "gain_spread": 0.06, "twist_spread": 0.06},
    "tau 0.3 s, 5 psi, readings +-0.5 psi": {
        "pressure_tau": 0.3,
        "hysteresis_psi": 5.0,
        "reading_noise_psi": 0.5,
    },
}
KEYS = ("tau_s", "metres_per_psi", "hysteresis_psi")


def trial(plant: dict[str, Any], seed: int, nominal_geometry: bool = False) -> dict[str, Any]:
    """One identification; the per-channel errors and the wall time. With
    ``nominal_geometry`` the gains are also fitted with the geometry held at the nominal
    arm's (``metres_per_psi_nominal_geometry``): what ignoring the geometry costs."""
    plant = dict(plant)
    noise = plant.pop("reading_noise_psi", 0.0)
    rig = SimIdentificationRig(PlantConfig(**plant), seed=seed, reading_noise_psi=noise)
    start = time.perf_counter()
    design = Design(n=rig.bank.channels)
    rec = run_experiment(rig, design.segments(), design.budget_s, design.settle_psi)
    found = estimate(rec, rig.model)
    wall = time.perf_counter() - start
    truth = rig.truth()
    out: dict[str, Any] = {"seed": seed, "wall_s": wall, "arm_time_s": found.metadata["arm_time_s"]}
    if nominal_geometry:
        fixed = fit_kinematics(rec, rig.model, fit_geometry=False)
        out["metres_per_psi_nominal_geometry"] = (
            fixed.metres_per_psi / np.asarray(truth["metres_per_psi"]) - 1.0
        ).tolist()
    for k in KEYS:
        out[k] = (np.asarray(getattr(found, k)) / np.asarray(truth[k]) - 1.0).tolist()
    out["dead_time_s"] = list(found.dead_time_s)
    out["pose_rms_mm"] = found.metadata["pose_rms_mm"]
    return out


def _seeds(text: str) -> list[int]:
    if "-" in text:
        a, b = text.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(s) for s in text.split(",")]


def summary(rows: list[dict[str, Any]]) -> dict[str, float]:
    """Max and median of |error| over every channel of every seed."""
    s: dict[str, float] = {}
    extra = (
        ["metres_per_psi_nominal_geometry"] if "metres_per_psi_nominal_geometry" in rows[0] else []
    )
    for k in (*KEYS, "dead_time_s", *extra):
        e = np.abs(np.concatenate([r[k] for r in rows]))
        s[f"{k}_max"] = float(e.max())
        s[f"{k}_median"] = float(np.median(e))
    s["wall_s_median"] = float(np.median([r["wall_s"] for r in rows]))
    s["arm_time_s_max"] = float(max(r["arm_time_s"] for r in rows))
    return s


def main() -> None:
    """Run every plant over the seeds; print a Markdown table; save the rows."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", type=_seeds, default=_seeds("1000-1019"))
    ap.add_argument("--plants", nargs="*", default=list(PLANTS), choices=list(PLANTS))
    ap.add_argument("--out", type=Path)
    ap.add_argument(
        "--nominal-geometry", action="store_true", help="also fit gains with the nominal geometry"
    )
    args = ap.parse_args()
    results: dict[str, dict[str, Any]] = {}
    for name in args.plants:
        rows = []
        for seed in args.seeds:
            rows.append(trial(PLANTS[name], seed, args.nominal_geometry))
            print(f"{name} seed {seed}: {json.dumps(summary(rows[-1:]))}", flush=True)
        results[name] = {"rows": rows, "summary": summary(rows)}
    print(
        "\n| plant | tau max / median | m/psi max / median | hysteresis max / median "
        "| dead time max | arm time max |"
    )
    print("| --- | --- | --- | --- | --- | --- |")
    for name, r in results.items():
        s = r["summary"]
        print(
            f"| {name} | {100 * s['tau_s_max']:.2f} / {100 * s['tau_s_median']:.2f} % "
            f"| {100 * s['metres_per_psi_max']:.2f} / {100 * s['metres_per_psi_median']:.2f} % "
            f"| {100 * s['hysteresis_psi_max']:.1f} / {100 * s['hysteresis_psi_median']:.1f} % "
            f"| {1e3 * s['dead_time_s_max']:.2f} ms | {s['arm_time_s_max']:.1f} s |"
        )
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
