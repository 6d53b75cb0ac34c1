"""The survey's plan on the model: each pair's second view is the first moved by the
baseline along the camera's own x axis with the camera's pointing kept; each first
view sees the bush's centre; every view keeps its margin from the known canes and every
ramp the planner's; the plan is repeatable; canes all around leave no plan."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import softarm
from softarm.harvest import HarvestConfig
from softarm.harvest.control import stack as rig
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.ik import ModelIK, planning_resolver
from softarm.harvest.control.survey import SurveySettings, plan_survey
from softarm.harvest.rigs.sim import options as sim_options
from softarm.harvest.rigs.sim import rig as sim_rig

CENTRE = np.array([0.02, 0.37, 0.38])  # a bush's berries, as Bush.generate places them
T_EE_C2 = np.eye(4)
T_EE_C2[2, 3] = -0.03
CFG = HarvestConfig()


def _ik(canes=()) -> ModelIK:
    arm = softarm.SoftArm.blackberry()
    clearance = Clearance(arm, canes, CFG.grasp_offset)
    return ModelIK(planning_resolver(arm), CFG, clearance=clearance)


def _plan(ik: ModelIK, settings: SurveySettings | None = None):
    home = np.full(ik.arm.n_actuators, CFG.home_elongation)
    return plan_survey(ik, np.zeros(ik.arm.n_actuators), home, T_EE_C2, CENTRE, settings)


def _camera(ik: ModelIK, q: np.ndarray) -> np.ndarray:
    return np.asarray(ik.arm.forward(q)) @ T_EE_C2


def test_pairs_move_the_camera_sideways_and_face_the_bush() -> None:
    ik = _ik()
    s = SurveySettings()
    plan = _plan(ik, s)
    assert len(plan.pairs) == s.pairs
    for first, second in plan.pairs:
        a, b = _camera(ik, first), _camera(ik, second)
        move = np.linalg.inv(a) @ b
        assert abs(abs(move[0, 3]) - s.baseline) < 2e-3  # the baseline, along x
        assert np.hypot(move[1, 3], move[2, 3]) < 2e-3
        # The pointing is kept (the resolver leaves the roll about it free).
        assert np.degrees(np.arccos(np.clip(move[2, 2], -1.0, 1.0))) < 3.0
        to_centre = CENTRE - a[:3, 3]
        cos = a[:3, 2] @ to_centre / np.linalg.norm(to_centre)
        assert cos >= np.cos(np.radians(s.max_angle))
        assert s.distance[0] <= np.linalg.norm(to_centre) <= s.distance[1]


def test_views_and_ramps_keep_clear_of_the_known_canes() -> None:
    # A cane across the front of the bush, where the views are.
    cane = softarm.PolynomialCurve(
        np.array([[-0.2, 0.4, 0.0, 0.0], [0.3, 0.0, 0.0, 0.0], [0.33, 0.0, 0.0, 0.0]]),
        (0.0, 1.0),
    )
    ik = _ik([cane])
    s = SurveySettings()
    plan = _plan(ik, s)
    assert plan.pairs  # the bush can still be seen
    home = np.full(ik.arm.n_actuators, CFG.home_elongation)
    last = np.zeros(ik.arm.n_actuators)
    for first, second in plan.pairs:
        assert ik.clearance.gap(first) >= s.margin and ik.clearance.gap(second) >= s.margin
        assert ik.clearance.path_gap(last, first) >= ik.ramp_margin
        assert ik.clearance.path_gap(second, home) >= ik.ramp_margin
        last = second


def test_the_plan_is_repeatable() -> None:
    a, b = _plan(_ik()), _plan(_ik())
    assert len(a.pairs) == len(b.pairs)
    for (p, q), (r, t) in zip(a.pairs, b.pairs, strict=True):
        assert np.array_equal(p, r) and np.array_equal(q, t)


def test_no_view_clear_of_the_canes_is_no_plan() -> None:
    # Canes through every place the camera could look from.
    canes = [
        softarm.PolynomialCurve(
            np.array([[x, 0.0, 0.0, 0.0], [0.0, 0.6, 0.0, 0.0], [z, 0.0, 0.0, 0.0]]), (0.0, 1.0)
        )
        for x in np.linspace(-0.3, 0.3, 13)
        for z in np.linspace(0.1, 0.6, 11)
    ]
    assert _plan(_ik(canes)).pairs == []


@pytest.mark.parametrize("avoid", [True, False])
def test_the_stack_avoids_the_canes_it_is_told_of(
    avoid: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    built: list[rig.ControlStack] = []

    def record(*args: Any, **kwargs: Any) -> rig.ControlStack:
        built.append(rig.build_control_stack(*args, **kwargs))
        return built[-1]

    monkeypatch.setattr(sim_rig, "build_control_stack", record)
    sim_rig.build_sim_rig(sim_options.SimRigOptions(n_berries=1, seed=1, avoid_canes=avoid))
    stack = built[0]
    cane = softarm.PolynomialCurve(np.zeros((3, 4)), (0.0, 1.0))
    before = list(stack.clearance.canes)
    stack.know_canes([cane])
    assert stack.clearance.canes == [cane] and stack.planner.clearance is stack.clearance
    # The canes known before stay the planner's fallback (ModelIK.plan).
    assert stack.planner.fallback is not None and stack.planner.fallback.canes == before
    assert stack.controller.obstacles == ([cane] if avoid else [])
    # A plan around the fallback's canes alone is followed avoiding those alone (the
    # refined map's canes it goes through would hold the arm); the next plan, all again.
    assert stack.planner.on_plan is not None
    stack.planner.on_plan(True)
    if avoid:
        assert stack.controller.obstacles == before
        assert stack.controller.clearance is stack.planner.fallback
    stack.planner.on_plan(False)
    assert stack.controller.obstacles == ([cane] if avoid else [])
    assert stack.controller.clearance is (stack.clearance if avoid else None)
