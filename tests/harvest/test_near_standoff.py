"""``[harvest] near_standoff``: a nearer pre-grasp pose where the plan keeps its cane
margins, ``standoff`` where it does not, and the stages that use the plan's distance."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from softarm import PolynomialCurve, SoftArm
from softarm.errors import ParameterError
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.ik import ModelIK, planning_resolver
from softarm.harvest_config import HarvestConfig
from softarm.sim.bush import Bush

NEAR = 0.035


@pytest.mark.parametrize("near", [-0.01, float("nan"), float("inf")])
def test_a_negative_or_non_finite_near_standoff_is_refused_by_name(near: float) -> None:
    with pytest.raises(ParameterError, match="near_standoff"):
        HarvestConfig(near_standoff=near)


@pytest.mark.parametrize("near", [0.0, 0.05, 0.06])
def test_a_near_standoff_off_or_not_below_the_standoff_plans_at_the_standoff(
    near: float,
) -> None:
    arm, planner, q, current, berry = _scene(None)
    planner.near_standoff = near
    plan = planner.plan(q, berry, current)
    assert plan is not None and planner.standoff == planner.cfg.standoff
    distance = _pre_grasp_distance(arm, plan[0], berry)
    assert distance == pytest.approx(planner.cfg.grasp_offset + planner.cfg.standoff, abs=1e-3)


def _scene(
    cane_side: float | None,
) -> tuple[SoftArm, ModelIK, np.ndarray, np.ndarray, np.ndarray]:
    """The planner with NEAR for the first berry of bush 3 (7 berries); with
    ``cane_side``, a straight cane across the approach planned without it, 3 cm short
    of the berry and ``cane_side`` (m) to its side."""
    arm = SoftArm.blackberry()
    berry = Bush.generate(arm, 3, 7).berries[0].position
    cfg = HarvestConfig(near_standoff=NEAR)
    q = np.full(arm.n_actuators, 0.0167)  # the harvest's home elongation
    clearance = None
    if cane_side is not None:
        free = ModelIK(planning_resolver(arm), cfg, seed=0, near_standoff=NEAR).plan(
            q, berry, arm.forward(q)
        )
        assert free is not None
        axis = free[1]
        side = np.cross(axis, [1.0, 0.0, 0.0])
        side /= np.linalg.norm(side)
        along = np.cross(axis, side)
        centre = berry - 0.03 * axis + cane_side * side
        coeffs = np.column_stack([centre - 0.1 * along, 0.2 * along, np.zeros(3), np.zeros(3)])
        clearance = Clearance(arm, [PolynomialCurve(coeffs, (0.0, 1.0))], cfg.grasp_offset)
    planner = ModelIK(planning_resolver(arm), cfg, seed=0, clearance=clearance, near_standoff=NEAR)
    return arm, planner, q, arm.forward(q), berry


def _pre_grasp_distance(arm: SoftArm, waypoints: list[np.ndarray], berry: np.ndarray) -> float:
    return float(np.linalg.norm(arm.forward(waypoints[-1])[:3, 3] - berry))


def test_without_canes_the_plan_ends_near_standoff_short_of_the_grasp_pose() -> None:
    arm, planner, q, current, berry = _scene(None)
    plan = planner.plan(q, berry, current)
    assert plan is not None
    assert planner.standoff == NEAR
    # The model's pre-grasp pose: its origin grasp_offset + NEAR from the berry (the
    # resolver's tolerance, well under the 15 mm between the two standoffs).
    distance = _pre_grasp_distance(arm, plan[0], berry)
    assert distance == pytest.approx(planner.cfg.grasp_offset + NEAR, abs=1e-3)


def test_a_cane_the_near_pose_passes_too_close_to_falls_back_on_the_standoff() -> None:
    # 4.5 cm to the side: the nearer pre-grasp pose has the gripper within the ramps'
    # 25 mm of the cane's surface, the farther one not (a cane 5 cm out lets both).
    arm, planner, q, current, berry = _scene(0.045)
    plan = planner.plan(q, berry, current)
    assert plan is not None
    assert planner.standoff == planner.cfg.standoff
    distance = _pre_grasp_distance(arm, plan[0], berry)
    assert distance == pytest.approx(planner.cfg.grasp_offset + planner.cfg.standoff, abs=1e-3)
    assert planner.clearance is not None
    start = q
    for q_way in plan[0]:
        assert planner.clearance.path_gap(start, q_way, 12) >= planner.ramp_margin
        start = q_way
    _, wide, q, current, berry = _scene(0.05)
    assert wide.plan(q, berry, current) is not None and wide.standoff == NEAR


def test_the_harvest_places_and_backs_out_to_the_plans_standoff(tmp_path: Path) -> None:
    from softarm.harvest import simulate
    from softarm.harvest.records.log import read_log

    log = tmp_path / "run.jsonl"
    report = simulate(1, 3, log=log, config=HarvestConfig(near_standoff=NEAR))
    assert report.berries[0].harvested
    events = list(read_log(log))
    plans = [e for e in events if e.get("kind") == "plan"]
    assert plans and all(p["standoff"] == NEAR for p in plans)
    # Placement's goal and the back-out's: grasp_offset + NEAR short of the berry.
    reach = HarvestConfig().grasp_offset + NEAR
    for state, k in (("initial_placement", -1), ("return_home", 0)):
        goals = [
            np.linalg.norm(np.subtract(e["goal"], e["target"]))
            for e in events
            if e.get("kind") == "step" and e["state"] == state and e.get("goal") is not None
        ]
        assert goals[k] == pytest.approx(reach, abs=1e-3), state
