"""The planning paper's simulations (tables 1-4) and the method comparison.

Each scenario is an arc chain of three segments of length 1 starting straight, a goal,
and curve obstacles (the equations come from the Rust core, ``_core.paper_scenario``).
The proposed method plans against the exact curves; the baseline plans against each
curve sampled as 1, 10, 50 or 100 points with the arm discretised into 10 points per
segment and brute-force distances, as the paper describes. Every plan is then judged
against the *true* curves: clearance along the whole backbone, checked at 8 interpolated
configurations per step, and a collision when it drops below :data:`COLLISION_DISTANCE`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softarm import _core

#: Scenario names, in the paper's order (tables 2, 3, 4).
SCENARIOS: tuple[str, ...] = ("line", "curve", "tree")
#: Point-set sizes the paper compares against.
POINT_MODELS: tuple[int, ...] = (1, 10, 50, 100)
#: Points per segment of the discretised arm in the baseline (table 1).
ARM_POINTS_PER_SEGMENT = 10
#: A true clearance below this (m) counts as a collision.
COLLISION_DISTANCE = 0.01
#: Interpolated configurations per step when judging a path.
SUBSTEPS = 8

#: The paper's tables: method -> (iterations, average computation time in s).
PAPER_TABLES: dict[str, dict[str, tuple[int, float]]] = {
    "line": {
        "proposed": (60, 0.2914),
        "1 point": (24, 0.0053),
        "10 points": (24, 0.0690),
        "50 points": (24, 0.4254),
        "100 points": (66, 1.6679),
    },
    "curve": {
        "proposed": (30, 0.2971),
        "1 point": (23, 0.0044),
        "10 points": (23, 0.0599),
        "50 points": (24, 0.2720),
        "100 points": (23, 0.5794),
    },
    "tree": {
        "proposed": (32, 0.7414),
        "1 point": (19, 0.1090),
        "10 points": (19, 0.7594),
        "50 points": (32, 5.7699),
    },
}


@dataclass(frozen=True)
class Scenario:
    """One simulation: name, goal (3,) and curve obstacles."""

    name: str
    goal: npt.NDArray[np.float64]
    curves: tuple[_core.PolynomialCurve, ...]

    @property
    def chain(self) -> _core.ArcChain:
        """The simulated arm (table 1): three segments of length 1."""
        return _core.ArcChain([1.0, 1.0, 1.0])


@dataclass(frozen=True)
class Result:
    """One method on one scenario."""

    scenario: str
    method: str
    iterations: int
    seconds: float
    reached: bool
    min_clearance: float
    collision: bool
    plan: _core.Plan


def load(name: str) -> Scenario:
    """The scenario called ``name`` ("line", "curve" or "tree")."""
    goal, curves = _core.paper_scenario(name)
    return Scenario(name=name, goal=goal, curves=tuple(curves))


def method_name(points: int | None) -> str:
    """ "proposed" for the exact curves, else "N point(s)"."""
    if points is None:
        return "proposed"
    return f"{points} point" if points == 1 else f"{points} points"


def run_method(scenario: Scenario, points: int | None, repeats: int = 20) -> Result:
    """Plans ``scenario`` with the exact curves (``points=None``) or with each curve as
    ``points`` points; times ``repeats`` plans and judges the path on the true curves."""
    chain = scenario.chain
    if points is None:
        planner = _core.PotentialFieldPlanner(chain)
        obstacles: list[_core.PolynomialCurve | _core.PointCloud] = list(scenario.curves)
    else:
        planner = _core.PotentialFieldPlanner(chain, arm_samples=ARM_POINTS_PER_SEGMENT)
        obstacles = [_core.PointCloud(c.sample(points)) for c in scenario.curves]
    q0 = chain.straight()
    plan = planner.plan(q0, scenario.goal, obstacles)
    times = []
    for _ in range(max(repeats, 1)):
        start = time.perf_counter()
        planner.plan(q0, scenario.goal, obstacles)
        times.append(time.perf_counter() - start)
    truth = _core.path_clearance(chain, plan.path, list(scenario.curves), SUBSTEPS)
    return Result(
        scenario=scenario.name,
        method=method_name(points),
        iterations=plan.iterations,
        seconds=float(np.median(times)),
        reached=plan.reached,
        min_clearance=truth,
        collision=truth < COLLISION_DISTANCE,
        plan=plan,
    )


def compare(name: str, repeats: int = 20) -> list[Result]:
    """The proposed method and every point model on scenario ``name``."""
    scenario = load(name)
    return [run_method(scenario, p, repeats) for p in (None, *POINT_MODELS)]


def verdict(results: list[Result]) -> str:
    """Whether the proposed method is collision-free and faster than every collision-free
    point model, as a sentence."""
    proposed = results[0]
    free = [r for r in results[1:] if not r.collision]
    faster = all(proposed.seconds < r.seconds for r in free)
    slower = [r.method for r in free if proposed.seconds >= r.seconds]
    parts = ["collision-free" if not proposed.collision else "COLLIDES"]
    if not free:
        parts.append("every point model collides")
    elif faster:
        parts.append("faster than every collision-free point model")
    else:
        parts.append("not faster than the collision-free " + ", ".join(slower))
    return "proposed method: " + "; ".join(parts)
