"""The placement planner's last-resort passes: what it tries before calling a berry
UNREACHABLE, with the cane margins unchanged."""

from __future__ import annotations

import numpy as np

from softarm import SoftArm
from softarm.harvest.clearance import Clearance
from softarm.harvest.config import HarvestConfig
from softarm.harvest.ik import ModelIK, planning_resolver
from softarm.sim.bush import Bush


def _scene(limit_room: float) -> tuple[ModelIK, np.ndarray, np.ndarray, Bush]:
    arm = SoftArm.blackberry()
    bush = Bush.generate(arm, 3, 7)
    clearance = Clearance(arm, [b.curve() for b in bush.branches], 0.03)
    planner = ModelIK(
        planning_resolver(arm), HarvestConfig(), seed=0, clearance=clearance,
        limit_room=limit_room,
    )  # fmt: skip
    q = np.full(arm.n_actuators, 0.0167)  # the harvest's home elongation
    return planner, q, arm.forward(q), bush


def test_a_grasp_on_the_joint_limits_is_tried_before_giving_up() -> None:
    # No solution of this arm keeps 1 m from its limits: every pass that asks for
    # joint-limit room fails, and only the last one (a grasp on the limits) can plan.
    planner, q, current, bush = _scene(limit_room=1.0)
    berry = bush.berries[0].position
    plan = planner.plan(q, berry, current)
    assert plan is not None
    waypoints, axis = plan
    assert np.degrees(np.arccos(np.clip(axis @ np.array([0.0, 1.0, 0.0]), -1, 1))) <= 20.0 + 1e-9
    _assert_ramps_clear(planner, q, waypoints)


def test_an_avoided_axis_is_not_planned_again_and_the_next_plan_is_as_clear() -> None:
    planner, q, current, bush = _scene(limit_room=0.001)
    berry = bush.berries[0].position
    first = planner.plan(q, berry, current)
    assert first is not None
    second = planner.plan(q, berry, current, avoid=[first[1]])
    assert second is not None
    waypoints, axis = second
    assert float(axis @ first[1]) < np.cos(np.radians(1.0))  # another axis of the cone
    assert np.degrees(np.arccos(np.clip(axis @ np.array([0.0, 1.0, 0.0]), -1, 1))) <= 20.0 + 1e-9
    _assert_ramps_clear(planner, q, waypoints)


def test_avoiding_every_axis_of_the_cone_leaves_no_plan() -> None:
    from softarm.geometry import cone_axes

    planner, q, current, bush = _scene(limit_room=0.001)
    every = cone_axes(planner.cfg.approach_axis, planner.cfg.approach_cone_deg)
    assert planner.plan(q, bush.berries[0].position, current, avoid=list(every)) is None


def _assert_ramps_clear(planner: ModelIK, q: np.ndarray, waypoints: list[np.ndarray]) -> None:
    """The canes keep the ramps' margin on every waypoint's ramp, from ``q`` on."""
    start = q
    for q_way in waypoints:
        assert planner.clearance.path_gap(start, q_way, 12) >= planner.ramp_margin
        start = q_way
