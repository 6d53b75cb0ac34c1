"""The placement planner's last-resort passes: what it tries before calling a berry
UNREACHABLE, with the cane margins unchanged."""

from __future__ import annotations

import numpy as np

from softarm import SoftArm
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.ik import ModelIK, planning_resolver
from softarm.harvest_config import HarvestConfig
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


def test_a_detour_goes_round_a_cane_the_straight_ramps_pass_too_near() -> None:
    # Seed 641's berry 12 (found UNREACHABLE by the sixth version): every pre-grasp pose
    # with room to the limits has its straight ramp from the ready pose 14-22 mm from
    # a cane on the model, under the 25 mm margin, and no via point on the approach line
    # clears it; the last pass goes round through a configuration of the arm's own.
    from softarm.geometry import cone_axes
    from softarm.harvest.control.ik import DETOUR
    from softarm.harvest.machine.targets import approach_pose
    from softarm.harvest.rigs.sim import options as sim_options
    from softarm.harvest.rigs.sim import rig as sim_rig

    rig = sim_rig.build_sim_rig(sim_options.SimRigOptions(n_berries=8, seed=641))
    planner = rig.machine.planner
    berry = next(b for b in rig.bush.berries if b.tag_id == 12).position
    q = np.full(rig.model.n_actuators, planner.cfg.home_elongation)
    current = rig.model.forward(q)
    plan = planner.plan(q, berry, current)
    assert plan is not None
    waypoints, axis = plan
    assert len(waypoints) == 2
    _assert_ramps_clear(planner, q, waypoints)
    # The pre-grasp pose is the last waypoint; the first is off the approach line, so it
    # is the detour, not a via point.
    c = planner.cfg
    pre = approach_pose(current, berry, axis, c.grasp_offset + c.standoff)
    assert np.linalg.norm(rig.model.forward(waypoints[1])[:3, 3] - pre[:3, 3]) < 2e-3
    mid = rig.model.forward(waypoints[0])[:3, 3] - berry
    assert np.linalg.norm(mid - (mid @ axis) * axis) > 0.01
    # No straight ramp, nor via point, was clear along this axis.
    ramp, standoff = planner.ramp_margin, c.standoff
    for via in (None, planner.via, 0.5 * planner.via):
        assert planner._path(q, berry, current, axis, via, 0.0, ramp, standoff) is None
    assert planner._path(q, berry, current, axis, DETOUR, 0.001, ramp, standoff)
    assert any(np.allclose(a, axis) for a in cone_axes(c.approach_axis, c.approach_cone_deg))


def test_a_berry_only_the_survey_canes_block_is_planned_around_the_fallback_canes() -> None:
    # A wall of canes 4 cm in front of the berry (phantoms, say) blocks every approach;
    # with C1's canes as the fallback the berry is planned around those, and the
    # planner says so and keeps its full clearance afterwards.
    import softarm

    planner, q, current, bush = _scene(limit_room=0.001)
    berry = bush.berries[0].position
    c1 = planner.clearance
    assert c1 is not None
    wall = [
        softarm.PolynomialCurve(
            np.array([[berry[0] - 0.3, 0.6, 0, 0], [berry[1] - 0.04, 0, 0, 0], [z, 0, 0, 0]]),
            (0.0, 1.0),
        )
        for z in berry[2] + np.linspace(-0.3, 0.3, 25)
    ]
    every = Clearance(c1.arm, [*c1.canes, *wall], c1.offset)
    planner.clearance = every
    told: list[bool] = []
    planner.on_plan = told.append
    assert planner.plan(q, berry, current) is None and not planner.fell_back
    planner.fallback = c1
    plan = planner.plan(q, berry, current)
    assert plan is not None and planner.fell_back and planner.clearance is every
    assert told == [False, True]  # each plan says whether it fell back
    planner.clearance = c1
    _assert_ramps_clear(planner, q, plan[0])


def test_a_start_that_converges_does_so_well_within_the_planners_step_cap() -> None:
    # The cap (ik.SOLVE_STEPS) only shortens the starts that never converge: from random
    # starts towards random poses of the arm's workspace (reachable and not), every
    # start that converges within 5x the cap does so within half of it.
    from softarm.harvest.control.ik import SOLVE_STEPS

    arm = SoftArm.blackberry()
    resolver = planning_resolver(arm)
    rng = np.random.default_rng(5)
    lo, hi = np.asarray(arm.lower), np.asarray(arm.upper)
    converged = []
    for _ in range(120):
        target = np.asarray(arm.forward(rng.uniform(lo, hi)))
        target[:3, 3] += rng.normal(0.0, 0.02, 3)  # some out of reach
        sol = resolver.solve(
            rng.uniform(lo, hi), target, max_steps=5 * SOLVE_STEPS,
            position_tolerance=1e-3, orientation_tolerance=0.02,
        )  # fmt: skip
        if sol.converged:
            converged.append(sol.steps)
    assert len(converged) >= 20
    assert max(converged) <= SOLVE_STEPS // 2
