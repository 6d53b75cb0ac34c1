"""Simulated harvests over plants that differ from the controller's model: regulator lag
and hysteresis (the results table of docs/harvest.md).

Every (plant, seed) is one bush; the table gives, per plant, the share of berries
harvested, the mean fine-positioning error (ground truth), cane-contact steps and the
median simulated seconds per berry. Run it on seeds the controller was not tuned on.

    python examples/harvest_plants.py --tau 0.08 0.3 0.8 1.0 --hysteresis 1.5 5 \
        --seeds 500 501 502 503 504 505 506 507 508 509 --berries 8 --jobs 16 \
        --out out/plants

The table of docs/harvest.md comes from its saved per-bush reports:

    python examples/harvest_plants.py --summarise runs/plants_680.json
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np


def one_trial(
    tau: float,
    hysteresis: float,
    seed: int,
    berries: int,
    lag_control: str = "predictor",
    calibrate: bool = False,
) -> dict:
    """Harvest one bush on one plant; returns the report as a dict plus the plant keys.
    With ``calibrate`` the plant is first calibrated (``softarm calibrate --sim``, 80
    poses) and the harvest runs on the fitted model, as on a real arm."""
    from softarm.harvest.rigs.sim import options as sim_options
    from softarm.harvest.rigs.sim import rig as sim_rig
    from softarm.sim.arm import PlantConfig

    plant = PlantConfig(pressure_tau=tau, hysteresis_psi=hysteresis)
    fields = {f.name for f in dataclasses.fields(sim_options.SimRigOptions)}
    if "plant" in fields:
        opts = sim_options.SimRigOptions(n_berries=berries, seed=seed, plant=plant)
        if "lag_control" in fields:
            opts.lag_control = lag_control
    else:  # a build older than the plant option: swap the plant's configuration in
        from softarm.sim.arm import SimulatedArm
        from softarm.sim.plant import ArmPlant

        def seeded(model, s):  # type: ignore[no-untyped-def]
            return ArmPlant(SimulatedArm(model, config=plant, seed=s))

        ArmPlant.seeded = staticmethod(seeded)  # type: ignore[method-assign]
        opts = sim_options.SimRigOptions(n_berries=berries, seed=seed)
    if calibrate:
        from softarm._core import SoftArm
        from softarm.calibration.sim import build_plant, calibrate_plant

        nominal = SoftArm.blackberry()
        # The rig's plant is drawn from seed + 1000 (softarm.harvest.rigs.sim.rig).
        opts.calibration = calibrate_plant(
            build_plant(nominal, plant, seed + 1000), plant, nominal, seed=seed
        )[0]
    start = time.perf_counter()
    report = sim_rig.build_sim_rig(opts).run().to_dict()
    report["wall_s"] = time.perf_counter() - start
    report["tau"] = tau
    report["hysteresis_psi"] = hysteresis
    report["lag_control"] = lag_control
    report["calibrated"] = calibrate
    return report


def summarise(reports: list[dict]) -> list[dict]:
    """One row per plant point."""
    rows = []
    for key in sorted({(r["tau"], r["hysteresis_psi"]) for r in reports}):
        group = [r for r in reports if (r["tau"], r["hysteresis_psi"]) == key]
        berries = [b for r in group for b in r["berries"]]
        harvested = [b for b in berries if b["harvested"]]
        errors = [b["true_position_error_mm"] for b in harvested]
        durations = [b["duration_s"] for b in berries if b.get("duration_s") is not None]
        rows.append(
            {
                "tau_s": key[0],
                "hysteresis_psi": key[1],
                "berries": len(berries),
                "harvested_pct": 100.0 * len(harvested) / max(len(berries), 1),
                "mean_fine_error_mm": float(np.mean(errors)) if errors else float("nan"),
                "contact_steps": sum(r["branch_contact_steps"] for r in group),
                "min_gap_mm": 1e3 * min(r["min_branch_gap_m"] for r in group),
                "median_sim_s_per_berry": float(np.median(durations)) if durations else 0.0,
                "wall_s_per_berry": sum(r["wall_s"] for r in group) / max(len(berries), 1),
            }
        )
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    ap.add_argument("--tau", type=float, nargs="+", default=[0.08, 0.3, 0.8, 1.0])
    ap.add_argument("--hysteresis", type=float, nargs="+", default=[1.5])
    ap.add_argument("--seeds", type=int, nargs="+", default=list(range(500, 505)))
    ap.add_argument("--berries", type=int, default=8)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument(
        "--out",
        type=Path,
        default=Path("out/plants"),
        help="where reports.json (per bush) and summary.json go",
    )
    ap.add_argument(
        "--lag-control",
        choices=["predictor", "bound"],
        default="predictor",
        help="the loop's handling of the lag (SimRigOptions.lag_control, docs/control.md)",
    )
    ap.add_argument(
        "--calibrate",
        action="store_true",
        help="calibrate each plant first and harvest on the fitted model (softarm calibrate)",
    )
    ap.add_argument(
        "--summarise",
        type=Path,
        metavar="REPORTS",
        help="print the table of a saved reports.json (the --out of a run); run nothing",
    )
    args = ap.parse_args()
    if args.summarise is not None:
        print_table(summarise(json.loads(args.summarise.read_text(encoding="utf-8"))))
        return
    args.out.mkdir(parents=True, exist_ok=True)
    trials = [(t, h, s) for t in args.tau for h in args.hysteresis for s in args.seeds]
    with ProcessPoolExecutor(args.jobs) as pool:
        futures = [
            pool.submit(one_trial, t, h, s, args.berries, args.lag_control, args.calibrate)
            for t, h, s in trials
        ]
        reports = []
        # Written as each bush finishes, so that a run stopped early keeps what it did.
        for done in as_completed(futures):
            reports.append(done.result())
            (args.out / "reports.json").write_text(json.dumps(reports, indent=1))
    rows = summarise(reports)
    (args.out / "summary.json").write_text(json.dumps(rows, indent=1))
    print_table(rows)


def print_table(rows: list[dict]) -> None:
    """The rows of :func:`summarise` as a Markdown table."""
    print(
        "| τ (s) | hysteresis (psi) | berries | harvested | mean fine error (mm) "
        "| contact steps | min gap (mm) | median sim s / berry | wall s / berry |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        print(
            f"| {r['tau_s']:g} | {r['hysteresis_psi']:g} | {r['berries']} | "
            f"{r['harvested_pct']:.1f} % | {r['mean_fine_error_mm']:.2f} | "
            f"{r['contact_steps']} | {r['min_gap_mm']:.1f} | "
            f"{r['median_sim_s_per_berry']:.1f} | {r['wall_s_per_berry']:.2f} |"
        )


if __name__ == "__main__":
    main()
