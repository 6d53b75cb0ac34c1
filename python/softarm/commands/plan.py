"""``softarm plan``: run one of the planning paper's simulations, print the comparison
with the point-set obstacle models, and optionally draw snapshots (figures 3-5)."""

from __future__ import annotations

import argparse

from softarm.planning.scenarios import SCENARIOS


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Registers ``softarm plan``."""
    p = subparsers.add_parser(
        "plan",
        help="potential-field planning among curve obstacles (planning paper)",
        description=__doc__,
    )
    p.add_argument("--scenario", choices=SCENARIOS, default="tree")
    p.add_argument("--plot", metavar="OUT.png", help="draw snapshots of the proposed plan")
    p.add_argument("--repeats", type=int, default=20, help="timed plans per method")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Runs the comparison; returns 0 when the proposed plan reached the goal without a
    collision, 1 otherwise."""
    from softarm.planning.plot import plot_plan
    from softarm.planning.scenarios import compare, load, verdict

    results = compare(args.scenario, args.repeats)
    print(f"scenario {args.scenario}")
    print(f"{'method':<12} {'iter':>5} {'time/plan':>11} {'reached':>8} {'clearance':>10} collision")
    for r in results:
        print(
            f"{r.method:<12} {r.iterations:>5} {r.seconds * 1e6:>8.0f} µs {str(r.reached):>8} "
            f"{r.min_clearance:>10.4f} {r.collision}"
        )
    print(verdict(results))
    if args.plot:
        out = plot_plan(load(args.scenario), results[0].plan, args.plot, f"scenario {args.scenario}")
        print(f"wrote {out}")
    proposed = results[0]
    return 0 if proposed.reached and not proposed.collision else 1
