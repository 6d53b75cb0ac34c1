"""pytest-benchmark: whole plans from Python (GIL released, loop in Rust), the proposed
method beside the point-set baselines of the planning paper."""

from __future__ import annotations

import pytest

from softarm import _core
from softarm.planning.scenarios import ARM_POINTS_PER_SEGMENT, load

pytest.importorskip("pytest_benchmark")


@pytest.mark.parametrize("name", ["line", "curve", "tree"])
@pytest.mark.parametrize("points", [None, 1, 10, 50, 100])
def test_plan(benchmark, name: str, points: int | None) -> None:  # type: ignore[no-untyped-def]
    sc = load(name)
    if points is None:
        planner = _core.PotentialFieldPlanner(sc.chain)
        obstacles: list[object] = list(sc.curves)
    else:
        planner = _core.PotentialFieldPlanner(sc.chain, arm_samples=ARM_POINTS_PER_SEGMENT)
        obstacles = [_core.PointCloud(c.sample(points)) for c in sc.curves]
    q0 = sc.chain.straight()
    plan = benchmark(planner.plan, q0, sc.goal, obstacles)
    assert plan.iterations > 0
