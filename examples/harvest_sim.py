"""Simulated harvests over several seeds: the numbers of docs/harvest.md.

Each seed draws a bush (berries along +Y, canes behind them), a true arm that differs
from the controller's model, and runs the full loop: synthetic eye-to-hand and
eye-in-hand images → ArUco vision → two-camera fusion (eq. 21–22) → hybrid resolver
(eq. 20) → safety layer → simulated pneumatic arm.

    python examples/harvest_sim.py --seeds 100 101 102 103 104 --berries 8 --out out/eval

A progress bar with the ETA runs on stderr and a line per bush as each one finishes;
the reports and logs go to --out.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from softarm.commands._args import Parser, int_range, non_negative_int, output_dir


def one_seed(seed: int, berries: int, out: Path, avoid: bool, gain: float | None) -> dict:
    """Run one bush and save its report; returns the report as a dict."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

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


def main(argv: list[str] | None = None) -> int:
    ap = Parser(prog="harvest_sim.py", description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--seeds", type=non_negative_int, nargs="+", default=[100, 101, 102, 103, 104],
        help="one simulated bush and arm per seed",
    )  # fmt: skip
    ap.add_argument("--berries", type=int_range(1, 1000), default=8, help="berries per bush")
    ap.add_argument("--jobs", type=int_range(1, 256), default=2, help="parallel processes")
    ap.add_argument("--out", type=output_dir, default="out/eval", help="output folder")
    ap.add_argument("--no-avoid", action="store_true", help="no cane repulsion in closed loop")
    ap.add_argument("--joint-limit-gain", type=float, help="closed-loop resolver γ (eq. 20)")
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    args = ap.parse_args(argv)

    from concurrent.futures import ProcessPoolExecutor, as_completed

    import numpy as np

    from softarm.commands._progress import Progress

    args.out.mkdir(parents=True, exist_ok=True)
    by_seed: dict[int, dict] = {}
    with (
        ProcessPoolExecutor(args.jobs) as pool,
        Progress(len(args.seeds), "bushes", "bush", args.quiet) as bar,
    ):
        futures = {
            pool.submit(
                one_seed, s, args.berries, args.out, not args.no_avoid, args.joint_limit_gain
            ): s
            for s in args.seeds
        }
        for future in as_completed(futures):
            seed, report = futures[future], future.result()
            by_seed[seed] = report
            bar.line(f"seed {seed}: {report['harvested']}/{report['attempted']} harvested")
            bar.advance()
    reports = [by_seed[s] for s in args.seeds]
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
