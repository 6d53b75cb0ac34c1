"""Issue 14 item 5: every core class pickles and deep-copies, and the copy computes the
same results as the original (process pools and distributed runs send these objects)."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import softarm
from softarm import _core

ARM = softarm.SoftArm.blackberry()
Q = np.linspace(0.0, 0.03, 9)
CHAIN = _core.ArcChain([1.0, 0.8, 0.6], lower=[0.5, -3, -6] * 3, upper=[1.5, 3, 6] * 3)
QC = np.array([1.0, 0.4, 0.3, 0.8, -0.6, 1.0, 0.6, 0.2, -2.0])
CURVE = _core.PolynomialCurve([[0.5, 0, 0.1], [0, 1, 0], [0, 0.2, 5]], (-2.0, 2.0))
SEGMENT = _core.Segment([0.5, -1.0, 1.5], [0.5, 1.0, 1.5])
CLOUD = _core.PointCloud(np.random.default_rng(7).uniform(-1, 2, (200, 3)))
MESH = _core.TriangleMesh(
    [[-1, -1, 2.5], [1, -1, 2.5], [0, 1, 2.5], [0, 0, 3.0]],
    [[0, 1, 2], [0, 1, 3]],
    tolerance=1e-5,
)
OBSTACLES = [CURVE, SEGMENT, CLOUD, MESH, np.array([0.3, 0.2, 1.0])]


def round_trips(obj: object) -> list[object]:
    return [pickle.loads(pickle.dumps(obj, protocol=p)) for p in (2, pickle.HIGHEST_PROTOCOL)] + [
        copy.deepcopy(obj),
        copy.copy(obj),
    ]


def same_closest(a: _core.Closest, b: _core.Closest) -> None:
    assert (a.distance, a.section, a.s, a.u) == (b.distance, b.section, b.s, b.u)
    assert np.array_equal(a.arm_point, b.arm_point)
    assert np.array_equal(a.obstacle_point, b.obstacle_point)


def test_section_and_arms_round_trip() -> None:
    section = ARM.sections[1]
    for s in round_trips(section):
        assert s == section and type(s) is softarm.Section
    for arm in round_trips(ARM):
        assert type(arm) is softarm.SoftArm and arm.sections == ARM.sections
        assert arm == ARM and hash(arm) == hash(ARM) and repr(arm) == repr(ARM)
        assert np.array_equal(arm.forward_batch(Q[None]), ARM.forward_batch(Q[None]))
        assert np.array_equal(arm.jacobian(Q), ARM.jacobian(Q))
    for chain in round_trips(CHAIN):
        assert type(chain) is _core.ArcChain
        assert np.array_equal(chain.lower, CHAIN.lower)
        assert np.array_equal(chain.upper, CHAIN.upper)
        assert np.array_equal(chain.frames(QC), CHAIN.frames(QC))


@pytest.mark.parametrize("obstacle", OBSTACLES[:4], ids=lambda o: type(o).__name__)
def test_obstacles_round_trip_with_identical_distances(obstacle: object) -> None:
    for copied in round_trips(obstacle):
        assert type(copied) is type(obstacle)
        same_closest(_core.closest(CHAIN, QC, copied), _core.closest(CHAIN, QC, obstacle))
        same_closest(_core.closest(ARM, Q, copied), _core.closest(ARM, Q, obstacle))


def test_obstacle_attributes_survive() -> None:
    c = pickle.loads(pickle.dumps(CURVE))
    assert np.array_equal(c.coeffs, CURVE.coeffs) and c.u_range == CURVE.u_range
    m = pickle.loads(pickle.dumps(MESH))
    assert np.array_equal(m.vertices, MESH.vertices)
    assert np.array_equal(m.triangles, MESH.triangles) and m.tolerance == MESH.tolerance
    p = pickle.loads(pickle.dumps(CLOUD))
    assert np.array_equal(p.points, CLOUD.points)
    s = pickle.loads(pickle.dumps(SEGMENT))
    assert np.array_equal(s.a, SEGMENT.a) and np.array_equal(s.b, SEGMENT.b)


def test_closest_round_trips() -> None:
    c = _core.closest(CHAIN, QC, CURVE)
    for copied in round_trips(c):
        same_closest(copied, c)  # type: ignore[arg-type]


def test_planner_and_plan_round_trip() -> None:
    goal, curves = _core.paper_scenario("curve")
    planner = _core.PotentialFieldPlanner(
        _core.ArcChain([1.0, 1.0, 1.0]), max_iterations=80, stall_window=7
    )
    q0 = np.array([1.0, 0.0, 0.0] * 3)
    plan = planner.plan(q0, goal, curves)
    for p in round_trips(planner):
        assert p.options == planner.options  # type: ignore[attr-defined]
        again = p.plan(q0, goal, round_trips(curves)[0])  # type: ignore[attr-defined]
        assert np.array_equal(again.path, plan.path)
        assert again.min_clearance == plan.min_clearance
    for copied in round_trips(plan):
        assert np.array_equal(copied.path, plan.path)  # type: ignore[attr-defined]
        assert np.array_equal(copied.tip_path, plan.tip_path)  # type: ignore[attr-defined]
        for name in ("reached", "iterations", "min_clearance", "termination"):
            assert getattr(copied, name) == getattr(plan, name)
    sampled = _core.PotentialFieldPlanner(ARM, arm_samples=7)
    assert pickle.loads(pickle.dumps(sampled)).options["arm_samples"] == 7


def test_resolver_pickles_and_steps_identically() -> None:
    import pickle

    import numpy as np

    import softarm

    arm = softarm.SoftArm.blackberry()
    res = softarm.Resolver(arm, "position", softarm.Gains(position_alpha=0.2))
    back = pickle.loads(pickle.dumps(res))
    q = np.full(arm.n_actuators, 0.015)
    target = arm.forward(np.full(arm.n_actuators, 0.01))[:3, 3]
    assert back.mode == "position" and back.gains == res.gains
    np.testing.assert_array_equal(back.step(q, target).q, res.step(q, target).q)


def test_soft_arm_repr_shows_its_geometry_and_equality_is_by_value() -> None:
    text = repr(ARM)
    assert text.startswith("SoftArm([Section(radius=") and text.count("Section(") == 3
    s = ARM.sections[0]
    assert f"rest_length={s.rest_length}" in text and f"upper={s.upper}" in text
    rebuilt = eval(text, {"SoftArm": softarm.SoftArm, "Section": softarm.Section})
    assert rebuilt == ARM and rebuilt is not ARM and len({rebuilt, ARM}) == 1
    other = softarm.SoftArm(ARM.sections[:2])
    assert other != ARM and ARM != "SoftArm" and ARM != ARM.sections
