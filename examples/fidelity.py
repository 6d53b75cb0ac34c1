"""Model fidelity: calibration and the harvest on a second physics (docs/fidelity.md).

    python examples/fidelity.py cc --seeds 1000-1019          # calibration, CC plant
    python examples/fidelity.py rod --seeds 1000-1002         # calibration, Cosserat plant
    python examples/fidelity.py harvest --seeds 1000 1001 --berries 5 --model calibrated

``cc``: a constant-curvature plant with +-6 % geometry, +-6 % gains, +-0.06 rad twists,
0.1 mm / 0.1 deg noise, 80 excitation poses; held-out error on 200 uniform commands
against the true poses. ``rod``: the Cosserat-rod plant of ``softarm harvest --sim``
(seed S + 1000, gravity upright and horizontal), driven through 80 excitation poses and
measured by the simulated tracker; held-out error on 40 other poses, nominal model vs
fitted model. ``harvest``: the simulated harvest on the rod, nominal or calibrated model.
Each part prints one markdown table row per run and appends JSON lines to --out.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

#: Gravity in the base frame: the arm upright (along +z), and held horizontal with
#: gravity across it (along -x of the base).
GRAVITY = {"upright": (0.0, 0.0, -9.81), "horizontal": (-9.81, 0.0, 0.0)}


def _seeds(values: list[str]) -> list[int]:
    out: list[int] = []
    for v in values:
        a, _, b = v.partition("-")
        out += list(range(int(a), int(b) + 1)) if b else [int(a)]
    return out


def _emit(out: Path, part: str, row: dict) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with (out / f"{part}.jsonl").open("a") as f:
        f.write(json.dumps(row) + "\n")


def run_cc(seeds: list[int], out: Path) -> None:
    from softarm.calibration import PoseErrorStats, calibrate
    from softarm.calibration.synthetic import synthetic_problem

    print(
        "| seed | nominal median (mm) | fitted median (mm) | fitted p95 (mm) "
        "| orientation median (deg) | fit (s) |"
    )
    print("| --- | --- | --- | --- | --- | --- |")
    for s in seeds:
        pb = synthetic_problem(s)
        t = time.perf_counter()
        cal = calibrate(pb.nominal, pb.fit_commands, pb.fit_poses)
        dt = time.perf_counter() - t
        st = cal.evaluate(pb.test_commands, pb.test_poses)
        nom = PoseErrorStats.of(pb.nominal.forward_batch(pb.test_commands), pb.test_poses)
        print(
            f"| {s} | {nom.position_median_mm:.2f} | {st.position_median_mm:.3f} | "
            f"{st.position_p95_mm:.3f} | {st.orientation_median_deg:.3f} | {dt:.2f} |",
            flush=True,
        )
        _emit(out, "cc", {"seed": s, "nominal": nom.as_dict(), "fitted": st.as_dict(), "s": dt})


def run_rod(seeds: list[int], gravities: list[str], out: Path) -> None:
    import numpy as np

    import softarm
    from softarm.calibration import PoseErrorStats, calibrate
    from softarm.calibration.excitation import excitation_set
    from softarm.calibration.sim import build_plant, calibrate_plant, true_poses
    from softarm.sim.arm import PlantConfig

    nominal = softarm.SoftArm.blackberry()
    print(
        "| gravity | seed | nominal median / p95 (mm) | fitted median / p95 (mm) "
        "| fitted + bias median / p95 (mm) | wall (s) |"
    )
    print("| --- | --- | --- | --- | --- | --- |")
    for g in gravities:
        cfg = PlantConfig(model="cosserat", gravity=GRAVITY[g])
        for s in seeds:
            t = time.perf_counter()
            plant = build_plant(nominal, cfg, s + 1000)
            cal, c, p = calibrate_plant(plant, cfg, nominal, seed=s, settle=0.6, average=0.3)
            biased = calibrate(nominal, c, p, bias=True)
            test_c = excitation_set(nominal, 40, seed=s + 77)
            truth = true_poses(plant, test_c, cfg, settle=0.6)
            out.mkdir(parents=True, exist_ok=True)
            np.savez(out / f"rod_{g}_{s}.npz", commands=c, poses=p, test_commands=test_c,
                     test_poses=truth)  # fmt: skip
            fit, fit_b = cal.evaluate(test_c, truth), biased.evaluate(test_c, truth)
            nom = PoseErrorStats.of(nominal.forward_batch(test_c), truth)
            wall = time.perf_counter() - t
            print(
                f"| {g} | {s} | {nom.position_median_mm:.2f} / {nom.position_p95_mm:.2f} | "
                f"{fit.position_median_mm:.2f} / {fit.position_p95_mm:.2f} | "
                f"{fit_b.position_median_mm:.2f} / {fit_b.position_p95_mm:.2f} | {wall:.0f} |",
                flush=True,
            )
            cal.save(out / f"model_{g}_{s}.toml")
            biased.save(out / f"model_bias_{g}_{s}.toml")
            row = {"gravity": g, "seed": s, "nominal": nom.as_dict(), "fitted": fit.as_dict()}
            _emit(out, "rod", {**row, "fitted_bias": fit_b.as_dict(), "wall_s": wall})


def run_harvest(
    seeds: list[int], gravities: list[str], berries: int, models: list[str], out: Path
) -> None:
    from softarm.calibration import Calibration
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.sim.arm import PlantConfig

    print(
        "| gravity | model | seed | harvested | mean error (mm) | contact steps | min gap (mm) "
        "| wall per berry (s) |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for g in gravities:
        for m in models:
            for s in seeds:
                cal = None
                if m != "nominal":
                    path = out / f"model{'_bias' if m == 'bias' else ''}_{g}_{s}.toml"
                    if not path.exists():
                        run_rod([s], [g], out)
                    cal = Calibration.load(path)
                cfg = PlantConfig(model="cosserat", gravity=GRAVITY[g])
                t = time.perf_counter()
                rig = build_sim_rig(
                    SimRigOptions(n_berries=berries, seed=s, plant=cfg, calibration=cal)
                )
                d = rig.run().to_dict()
                wall = (time.perf_counter() - t) / berries
                errs = [
                    b.get("true_position_error_mm") or b["position_error_mm"]
                    for b in d["berries"]
                    if b["harvested"]
                ]
                mean = sum(errs) / len(errs) if errs else math.nan
                print(
                    f"| {g} | {m} | {s} | {d['harvested']}/{d['attempted']} | {mean:.2f} | "
                    f"{d['branch_contact_steps']} | {1e3 * d['min_branch_gap_m']:.1f} | "
                    f"{wall:.0f} |",
                    flush=True,
                )
                faults = [b["fault"] for b in d["berries"] if b["fault"]]
                _emit(out, "harvest", {"gravity": g, "model": m, "seed": s, "harvested":
                      d["harvested"], "attempted": d["attempted"], "mean_error_mm": mean,
                      "contacts": d["branch_contact_steps"], "faults": faults,
                      "wall_per_berry_s": wall})  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="fidelity.py", description=__doc__.split("\n\n")[0])
    # Optional for argparse so that an unknown option is reported before a missing part.
    ap.add_argument("part", nargs="?", choices=["cc", "rod", "harvest"])
    ap.add_argument("--seeds", nargs="+", default=["1000-1019"], help="seeds or ranges a-b")
    ap.add_argument("--gravity", nargs="+", choices=sorted(GRAVITY), default=sorted(GRAVITY))
    ap.add_argument("--berries", type=int, default=5)
    ap.add_argument("--model", nargs="+", choices=["nominal", "calibrated", "bias"],
                    default=["nominal", "calibrated"])  # fmt: skip
    ap.add_argument("--out", type=Path, default=Path("out/fidelity"))
    a = ap.parse_args(argv)
    if a.part is None:
        ap.error("the part to run is required: cc, rod or harvest")
    seeds = _seeds(a.seeds)
    if a.part == "cc":
        run_cc(seeds, a.out)
    elif a.part == "rod":
        run_rod(seeds, a.gravity, a.out)
    else:
        run_harvest(seeds, a.gravity, a.berries, a.model, a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
