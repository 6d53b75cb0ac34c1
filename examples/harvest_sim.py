"""Simulated harvests over several seeds: the numbers of docs/harvest.md.

Each seed draws a bush (berries along +Y, canes behind them), a true arm that differs
from the controller's model, and runs the full loop: synthetic eye-to-hand and
eye-in-hand images → ArUco vision → two-camera fusion (eq. 21–22) → hybrid resolver
(eq. 20) → safety layer → simulated pneumatic arm.

    python examples/harvest_sim.py --seeds 100 101 102 103 104 --berries 8 --out out/eval
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from softarm.harvest.sim_rig import SimRigOptions, build_sim_rig


def one_seed(seed: int, berries: int, out: Path, avoid: bool, gain: float | None) -> dict:
    """Run one bush and save its report; returns the report as a dict."""
    opts = SimRigOptions(
        n_berries=berries,
        seed=seed,
        log_path=out / f"seed{seed}.jsonl",
        avoid_canes=avoid,
        joint_limit_gain=gain,
    )
    report = build_sim_rig(opts).run().to_dict()
    (out / f"seed{seed}.json").write_text(json.dumps(report, indent=2))
    return report


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[100, 101, 102, 103, 104])
    ap.add_argument("--berries", type=int, default=8)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("out/eval"))
    ap.add_argument("--no-avoid", action="store_true", help="no cane repulsion in closed loop")
    ap.add_argument("--joint-limit-gain", type=float, help="closed-loop resolver γ (eq. 20)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    with ProcessPoolExecutor(args.jobs) as pool:
        futures = [
            pool.submit(
                one_seed, s, args.berries, args.out, not args.no_avoid, args.joint_limit_gain
            )
            for s in args.seeds
        ]
        reports = [f.result() for f in futures]
    rows = [b for r in reports for b in r["berries"]]
    errors = [b["true_position_error_mm"] for b in rows if b["harvested"]]
    print("| seed | harvested | mean error (mm) | max error (mm) | min cane gap (mm) | contacts |")
    print("| --- | --- | --- | --- | --- | --- |")
    for r in reports:
        e = [b["true_position_error_mm"] for b in r["berries"] if b["harvested"]]
        print(
            f"| {r['seed']} | {r['harvested']}/{r['attempted']} | "
            f"{np.mean(e) if e else float('nan'):.3f} | {max(e, default=float('nan')):.3f} | "
            f"{1e3 * r['min_branch_gap_m']:.1f} | {r['branch_contact_steps']} |"
        )
    faults: dict[str, int] = {}
    for b in rows:
        if b["fault"]:
            faults[b["fault"]] = faults.get(b["fault"], 0) + 1
    print(
        f"\nall: {sum(b['harvested'] for b in rows)}/{len(rows)} harvested "
        f"({100 * np.mean([b['harvested'] for b in rows]):.1f} %), mean fine-positioning error "
        f"{np.mean(errors):.3f} mm (max {np.max(errors):.3f}), faults {faults}, "
        f"contact steps {sum(r['branch_contact_steps'] for r in reports)}, min gap "
        f"{1e3 * min(r['min_branch_gap_m'] for r in reports):.1f} mm"
    )


if __name__ == "__main__":
    main()
