"""Every transition of the harvesting state machine, on fast fakes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softarm.hardware.pressure_map import METRES_PER_PSI
from softarm.harvest import BerryTarget, FaultReason, HarvestConfig, HarvestState
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.targets import grasp_point
from softarm.harvest.runs.policy import run_targets

from .fakes import BERRIES, commanded_before_the_vent, make_rig

S = HarvestState
HAPPY = [S.IDLE, S.INITIAL_PLACEMENT, S.FINE_POSITIONING, S.GRASP, S.RETURN_HOME, S.DONE]


def test_happy_path_visits_every_state_in_order_and_ends_at_rest() -> None:
    rig = make_rig()
    report = run_targets(rig.machine.run_berry, [BerryTarget(1), BerryTarget(2)], rig.machine.log)
    assert report.success_rate == 1.0
    for tag in (1, 2):
        assert rig.transitions(tag) == HAPPY
    for b in report.berries:
        assert b.final_state is S.DONE and b.fault is None
        assert b.position_error_mm <= 1.0
        assert b.orientation_error_deg < 1e-6
        assert b.duration_s > 0 and b.steps > 0
        assert b.cameras["eye_to_hand"] > 0 and b.cameras["eye_in_hand"] > 0
    home_psi = rig.machine.config.home_elongation / METRES_PER_PSI
    assert np.allclose(rig.plant.psi, home_psi)  # back at the ready pose
    assert not rig.gripper.closed  # berry dropped at home
    # The way home is closed on the tracked cube (goals in the step log), not ramped.
    kinds = [r["kind"] for r in rig.machine.log.records]
    assert "return_open_loop" not in kinds
    home_steps = [
        r for r in rig.machine.log.records if r["kind"] == "step" and r["state"] == "return_home"
    ]
    assert any(r["goal"] is not None for r in home_steps)
    assert rig.bank.vent_log[-1].reason == "startup"  # never vented: no fault


def test_fine_positioning_puts_the_grasp_point_on_the_berry() -> None:
    rig = make_rig()
    rig.machine.run_berry(BerryTarget(1))
    steps = [r for r in rig.machine.log.records if r["kind"] == "step"]
    last_fine = [r for r in steps if r["state"] == "fine_positioning"][-1]
    pose = np.array(last_fine["pose"])
    assert np.linalg.norm(grasp_point(pose, 0.03) - BERRIES[1]) <= 1e-3


def test_unripe_berry_is_released_and_skipped() -> None:
    rig = make_rig()
    rig.ripeness.values[1] = 0.2
    result = rig.machine.run_berry(BerryTarget(1))
    assert rig.transitions(1) == HAPPY
    assert result.skipped_unripe and not result.harvested
    assert result.final_state is S.DONE
    assert not rig.gripper.closed
    ripeness = [r for r in rig.machine.log.records if r["kind"] == "ripeness"]
    assert ripeness[0]["value"] == 0.2


def test_unreachable_berry_faults_vents_and_the_run_goes_on() -> None:
    rig = make_rig()
    report = run_targets(rig.machine.run_berry, [BerryTarget(3), BerryTarget(1)], rig.machine.log)
    first, second = report.berries
    assert first.fault is FaultReason.UNREACHABLE and first.final_state is S.FAULT
    # Backed out home before the vent: the arm relaxes from the ready pose, not in the bush.
    assert rig.transitions(3) == [S.IDLE, S.INITIAL_PLACEMENT, S.RETURN_HOME, S.FAULT]
    assert commanded_before_the_vent(rig) == rig.machine.home.tolist()
    assert "unreachable" in rig.bank.vent_log[1].reason
    assert second.harvested and report.stopped is None
    assert report.success_rate == 0.5


def test_timeout_in_fine_positioning_faults_and_vents() -> None:
    rig = make_rig(config=HarvestConfig(fine_timeout=0.3, fine_budget=0.2, grasp_workspace=1e-4))
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.TIMEOUT
    assert rig.transitions(1)[-3:] == [S.FINE_POSITIONING, S.RETURN_HOME, S.FAULT]
    assert commanded_before_the_vent(rig) == rig.machine.home.tolist()
    assert rig.vented()


def test_a_retreat_that_fails_vents_where_it_is_with_the_first_fault(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    config = HarvestConfig(
        fine_timeout=0.3, fine_budget=0.2, grasp_workspace=1e-4, home_timeout=0.01
    )
    rig = make_rig(config=config)
    transport = rig.machine.servo.transport
    ramp = transport.ramp

    def stuck(watch: object, stage: S, *args: object, **kwargs: object) -> object:
        # The ramp home (after the closed loop ran out of its 10 ms) cannot finish.
        if stage is S.RETURN_HOME:
            raise Fault(FaultReason.TIMEOUT, "return_home: ramp not done in time")
        return ramp(watch, stage, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(transport, "ramp", stuck)
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.TIMEOUT
    fault = next(r for r in rig.machine.log.records if r["kind"] == "fault")
    assert fault["detail"].startswith("fine_positioning: error")
    assert any(r["kind"] == "retreat_failed" for r in rig.machine.log.records)
    assert commanded_before_the_vent(rig) != rig.machine.home.tolist()
    assert rig.vented()


def test_fine_budget_grasps_within_the_gripper_workspace() -> None:
    # A tolerance no step can meet: after the budget the ±1 cm workspace is enough.
    rig = make_rig(config=HarvestConfig(fine_tolerance=1e-9, fine_budget=1.0))
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested
    assert any(r["kind"] == "fine_budget" for r in rig.machine.log.records)


def test_report_json_has_one_entry_per_berry_with_the_required_fields() -> None:
    rig = make_rig()
    report = run_targets(rig.machine.run_berry, [BerryTarget(1), BerryTarget(3)], rig.machine.log)
    data = json.loads(json.dumps(report.to_dict(), allow_nan=False))
    assert data["success_rate"] == 0.5
    assert [b["tag_id"] for b in data["berries"]] == [1, 3]
    for b in data["berries"]:
        for key in ("target", "harvested", "position_error_mm", "orientation_error_deg"):
            assert key in b
        assert b["final_state"] in ("done", "fault")
        assert len(b["target"]) == 3 and b["duration_s"] > 0
    assert data["berries"][1]["fault"] == "unreachable"


def test_positioning_only_ends_done_after_fine_positioning() -> None:
    rig = make_rig()
    result = rig.machine.run_berry(BerryTarget(1), grasp=False)
    assert rig.transitions(1) == [S.IDLE, S.INITIAL_PLACEMENT, S.FINE_POSITIONING, S.DONE]
    assert result.final_state is S.DONE and not result.harvested and not rig.gripper.closed


class _Planner:
    """Plans a fixed waypoint and a tilted axis, or nothing."""

    def __init__(self, waypoints, axis) -> None:
        self.waypoints, self.axis, self.calls = waypoints, axis, 0

    def plan(self, q, berry, current, avoid=()):
        self.calls += 1
        return None if self.waypoints is None else (self.waypoints, self.axis)


def test_a_plan_is_ramped_to_then_servoed_along_its_axis() -> None:
    rig = make_rig()
    planner = _Planner([np.full(3, 0.01)], np.array([0.0, 1.0, 0.0]))
    rig.machine.planner = planner
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and planner.calls == 1
    plan = next(r for r in rig.machine.log.records if r["kind"] == "plan")
    assert plan["q"] == [[0.01, 0.01, 0.01]]


def test_no_plan_is_unreachable() -> None:
    rig = make_rig()
    rig.machine.planner = _Planner(None, None)
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.UNREACHABLE
    assert rig.transitions(1) == [S.IDLE, S.INITIAL_PLACEMENT, S.FAULT]
    assert rig.vented()


def test_placement_held_by_a_joint_limit_hands_over_to_fine_positioning() -> None:
    """Placed in position but a limit holds the pointing 20° off: not a fault; fine
    positioning takes over and grasps inside the gripper's ±1 cm (III-D)."""
    rig = make_rig()
    true_pose = rig.plant.pose
    tilt = np.eye(4)
    c, s = np.cos(np.radians(20.0)), np.sin(np.radians(20.0))
    tilt[1:3, 1:3] = [[c, -s], [s, c]]
    rig.plant.pose = lambda: true_pose() @ tilt  # type: ignore[method-assign]
    controller = rig.machine.servo.controller
    step = controller.step
    controller.step = lambda q, t, cur: (step(q, t, cur)[0], True)  # type: ignore[method-assign]
    result = rig.machine.run_berry(BerryTarget(1))
    events = [r["kind"] for r in rig.machine.log.records]
    assert "placement_limit" in events
    assert rig.transitions(1)[:3] == [S.IDLE, S.INITIAL_PLACEMENT, S.FINE_POSITIONING]
    assert result.fault is None and result.harvested
