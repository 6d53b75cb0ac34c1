"""``softarm plan``: run one of the planning paper's simulations, print the comparison
with the point-set obstacle models, and optionally draw snapshots (figures 3-5)."""

from __future__ import annotations

import argparse
import json

from softarm.commands._args import image_file, int_range
from softarm.formatting import rounded
from softarm.planning.scenarios import SCENARIOS


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Registers ``softarm plan``."""
    p = subparsers.add_parser(
        "plan",
        help="potential-field planning among curve obstacles (planning paper)",
        description=__doc__,
    )
    p.add_argument("--scenario", choices=SCENARIOS, default="tree", help="which simulation")
    p.add_argument(
        "--plot", metavar="OUT.png", type=image_file, help="draw snapshots of the proposed plan"
    )
    p.add_argument(
        "--repeats", type=int_range(1, 10_000), default=20, help="timed plans per method"
    )
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Runs the comparison; returns 0 when the proposed plan reached the goal without a
    collision, 1 otherwise."""
    from softarm.planning.scenarios import compare, load, verdict

    results = compare(args.scenario, args.repeats)
    if args.json:
        rows = [
            {
                "method": r.method,
                "iterations": r.iterations,
                "seconds_per_plan": r.seconds,
                "reached": r.reached,
                "min_clearance_m": r.min_clearance,
                "collision": r.collision,
            }
            for r in results
        ]
        doc = {"scenario": args.scenario, "repeats": args.repeats, "results": rows}
        print(json.dumps(rounded({**doc, "verdict": verdict(results)}), indent=2))
    else:
        print(f"scenario {args.scenario}")
        print(
            f"{'method':<12} {'iter':>5} {'time/plan':>11} {'reached':>8} {'clearance':>10} "
            "collision"
        )
        for r in results:
            print(
                f"{r.method:<12} {r.iterations:>5} {r.seconds * 1e6:>8.0f} µs {r.reached!s:>8} "
                f"{r.min_clearance:>10.4f} {r.collision}"
            )
        print(verdict(results))
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from softarm.planning.plot import plot_plan

        out = plot_plan(
            load(args.scenario),
            results[0].plan,
            args.plot,
            f"scenario {args.scenario}",
            baselines=results[1:],
        )
        if not args.json:
            print(f"wrote {out}")
    proposed = results[0]
    return 0 if proposed.reached and not proposed.collision else 1
