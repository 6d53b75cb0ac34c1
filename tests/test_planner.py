"""softarm.PotentialFieldPlanner and the planning paper's scenarios."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm import _core, errors
from softarm.planning import COLLISION_DISTANCE, compare, load


@pytest.mark.parametrize("name", ["line", "curve", "tree"])
def test_proposed_method_reaches_and_stays_clear(name: str) -> None:
    sc = load(name)
    planner = softarm.PotentialFieldPlanner(sc.chain)
    plan = planner.plan(sc.chain.straight(), sc.goal, list(sc.curves))
    assert plan.reached and plan.termination == "reached"
    assert plan.path.shape == (plan.iterations + 1, 9) and plan.path.dtype == np.float64
    assert plan.tip_path.shape == (plan.iterations + 1, 3)
    assert np.linalg.norm(plan.tip_path[-1] - sc.goal) <= 0.01
    # Clearance is measured exactly at every step and is never negative.
    per_step = [min(softarm.closest(sc.chain, q, c).distance for c in sc.curves) for q in plan.path]
    assert min(per_step) >= 0.0
    assert plan.min_clearance == pytest.approx(min(per_step), abs=1e-12)
    assert _core.path_clearance(sc.chain, plan.path, list(sc.curves), 8) > COLLISION_DISTANCE


def test_sparse_point_models_collide_in_the_curve_scene() -> None:
    results = compare("curve", repeats=1)
    assert results[0].method == "proposed" and not results[0].collision
    assert results[1].method == "1 point" and results[1].collision


def test_mixed_obstacles_and_soft_arm_limits() -> None:
    arm = softarm.SoftArm.blackberry()
    goal = arm.forward([0.03, 0.0, 0.01, 0.0, 0.03, 0.01, 0.01, 0.0, 0.03])[:3, 3]
    planner = softarm.PotentialFieldPlanner(
        arm,
        max_tip_step=0.01,
        goal_tolerance=0.002,
        influence_distance=0.03,
        repulsion_gain=1e-8,
        stall_tolerance=1e-5,
    )
    obstacles = [
        softarm.Segment([0.1, -0.2, 0.3], [0.1, 0.2, 0.3]),
        softarm.PointCloud([[-0.1, 0.0, 0.2], [-0.1, 0.05, 0.25]]),
        softarm.PolynomialCurve([[0.0, 0.0], [0.15, 0.0], [0.0, 1.0]], (0.0, 0.5)),
        [0.0, -0.2, 0.2],
    ]
    plan = planner.plan(np.full(9, 0.01), goal, obstacles)
    assert np.all(plan.path >= arm.lower) and np.all(plan.path <= arm.upper)
    assert plan.min_clearance > 0.0
    assert np.linalg.norm(plan.tip_path[-1] - goal) < 0.5 * np.linalg.norm(plan.tip_path[0] - goal)


def test_planner_errors() -> None:
    chain = softarm.ArcChain([1.0, 1.0, 1.0])
    planner = softarm.PotentialFieldPlanner(chain)
    with pytest.raises(errors.ShapeError, match="goal"):
        planner.plan(chain.straight(), [1.0, 0.0], [])
    with pytest.raises(errors.OutOfRangeError, match="q0"):
        planner.plan(np.full(9, 5.0), [1.0, 0.0, 1.0], [])
    with pytest.raises(errors.ParameterError, match="influence_distance"):
        softarm.PotentialFieldPlanner(chain, influence_distance=0.0)
    with pytest.raises(errors.InputError, match="obstacles"):
        planner.plan(chain.straight(), [1.0, 0.0, 1.0], ["branch"])
    sampled = softarm.PotentialFieldPlanner(chain, arm_samples=10)
    with pytest.raises(errors.ParameterError, match=r"obstacles\[0\]"):
        sampled.plan(chain.straight(), [1.0, 0.0, 1.0], list(load("line").curves))
    with pytest.raises(errors.ParameterError, match="scenario"):
        _core.paper_scenario("forest")


def test_plan_command_writes_a_plot(tmp_path: Path) -> None:
    from softarm.commands import plan

    out = tmp_path / "tree.png"
    status = plan.run(argparse.Namespace(scenario="tree", plot=str(out), repeats=1, json=False))
    assert status == 0
    assert out.stat().st_size > 10_000
