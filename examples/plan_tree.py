"""Plan a three-segment arc chain to a goal behind six tree-branch curves (simulation 3
of the planning paper), and draw snapshots of the motion into --out.

    python examples/plan_tree.py --out out/examples
"""

from __future__ import annotations

import sys

from softarm.commands._args import Parser, output_dir


def main(argv: list[str] | None = None) -> int:
    parser = Parser(prog="plan_tree.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=output_dir, default="out/examples", help="output folder")
    args = parser.parse_args(argv)

    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    import softarm
    from softarm.planning.plot import plot_plan
    from softarm.planning.scenarios import load

    scenario = load("tree")  # goal (1, 0.7, 1.45) and the six branch curves of table 4
    chain = softarm.ArcChain([1.0, 1.0, 1.0])
    planner = softarm.PotentialFieldPlanner(chain, influence_distance=0.1)
    # Obstacles can be mixed: the curves, plus a point cloud of leaves and a stake.
    leaves = softarm.PointCloud(np.random.default_rng(0).normal([1.4, 1.3, 1.8], 0.08, (500, 3)))
    stake = softarm.Segment([1.6, -0.5, 0.0], [1.6, -0.5, 1.2])
    obstacles = [*scenario.curves, leaves, stake]
    plan = planner.plan(chain.straight(), scenario.goal, obstacles)
    print(plan)
    closest = min(
        (softarm.closest(chain, plan.path[-1], o) for o in obstacles), key=lambda c: c.distance
    )
    print(
        f"final clearance {closest.distance:.3f} m "
        f"at section {closest.section}, s = {closest.s:.2f}"
    )
    args.out.mkdir(parents=True, exist_ok=True)
    out = args.out / "plan_tree.png"
    plot_plan(scenario, plan, out, "simulation 3: tree")
    print(f"wrote {out}")
    return 0 if plan.reached else 1


if __name__ == "__main__":
    sys.exit(main())
