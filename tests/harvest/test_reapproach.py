"""Re-approach: a berry the arm saturated short of along its planned axis is backed out
from and planned again along another axis of the cone (HarvestConfig.reapproaches)."""

from __future__ import annotations

import numpy as np

from softarm.harvest import BerryTarget, FaultReason, HarvestConfig, HarvestState
from softarm.harvest.machine.states import FAULTS_THAT_STOP

from .fakes import BERRIES, FakeController, make_rig

S = HarvestState
SQUARE = np.array([0.0, 1.0, 0.0])
TILTED = np.array([0.0, np.cos(np.radians(2.0)), np.sin(np.radians(2.0))])


class AxisBoundController(FakeController):
    """The fake arm, except that along the ``blocked`` approach axes (the target's z axis)
    it stays where it is, saturated: as a true arm that needs a channel past its limit to
    face the berry that way. With ``only_at`` a berry, only in fine positioning on it;
    with ``short`` (m), only that far from the target; each one for all the blocked axes
    or a list with one per axis."""

    def __init__(
        self,
        blocked: list[np.ndarray],
        only_at: np.ndarray | list[np.ndarray | None] | None = None,
        short: float | list[float] = 0.0,
        saturated: bool = True,
    ) -> None:
        super().__init__()
        self.blocked = blocked
        self.only_at = only_at if isinstance(only_at, list) else [only_at] * len(blocked)
        self.short = short if isinstance(short, list) else [short] * len(blocked)
        self.saturated = saturated

    def step(self, q, target, current):
        left = float(np.linalg.norm(target[:3, 3] - current[:3, 3]))
        for axis, at, short in zip(self.blocked, self.only_at, self.short, strict=True):
            near = at is None or _grasp_goal_near(target, current, at)
            blocked = float(target[:3, 2] @ axis) > np.cos(np.radians(0.5))
            if near and blocked and (short == 0 or left <= short):  # held short of it
                return np.array(q, dtype=np.float64), self.saturated
        return super().step(q, target, current)


def _grasp_goal_near(target: np.ndarray, current: np.ndarray, berry: np.ndarray) -> bool:
    """Whether ``target`` puts the grasp point (3 cm ahead along the current z axis, as
    ``tool_pose`` does) on ``berry``: fine positioning."""
    return bool(np.linalg.norm(target[:3, 3] + 0.03 * current[:3, 2] - berry) < 1e-3)


class AxisPlanner:
    """Plans one waypoint along the first of ``axes`` not avoided; records ``avoid``."""

    def __init__(self, axes: list[np.ndarray]) -> None:
        self.axes, self.avoided = axes, []

    def plan(self, q, berry, current, avoid=()):
        self.avoided.append([np.asarray(a) for a in avoid])
        for axis in self.axes:
            if not any(float(axis @ a) > np.cos(np.radians(1.0)) for a in avoid):
                return [np.full(3, 0.01)], axis
        return None


def _rig(
    blocked: list[np.ndarray],
    config: HarvestConfig | None = None,
    only_at: np.ndarray | list[np.ndarray | None] | None = None,
    short: float | list[float] = 0.0,
):
    rig = make_rig(config=config)
    planner = AxisPlanner([SQUARE, TILTED])
    rig.machine.planner = planner
    rig.machine.servo.controller = AxisBoundController(blocked, only_at, short)
    return rig, planner


def test_a_stall_on_the_planned_axis_backs_out_home_and_reapproaches_along_another() -> None:
    rig, planner = _rig([SQUARE])
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and result.fault is None
    assert rig.transitions(1) == [
        S.IDLE, S.INITIAL_PLACEMENT, S.RETURN_HOME, S.INITIAL_PLACEMENT,
        S.FINE_POSITIONING, S.GRASP, S.RETURN_HOME, S.DONE,
    ]  # fmt: skip
    assert len(planner.avoided) == 2 and not planner.avoided[0]
    assert np.allclose(planner.avoided[1], [SQUARE])
    assert np.allclose(rig.machine.axis, TILTED)
    assert [v.reason for v in rig.bank.vent_log] == ["startup"]  # backed out, never vented
    why = [r["why"] for r in rig.machine.log.records if r["kind"] == "transition"]
    assert any(w.startswith("re-approach: initial_placement: saturated") for w in why)


def test_a_stall_in_fine_positioning_reapproaches_from_home() -> None:
    rig, planner = _rig([SQUARE], only_at=BERRIES[1])
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested
    assert rig.transitions(1) == [
        S.IDLE, S.INITIAL_PLACEMENT, S.FINE_POSITIONING, S.RETURN_HOME, S.INITIAL_PLACEMENT,
        S.FINE_POSITIONING, S.GRASP, S.RETURN_HOME, S.DONE,
    ]  # fmt: skip
    assert np.allclose(planner.avoided[1], [SQUARE])
    assert result.position_error_mm <= 1.0  # the errors of the attempt that grasped


def test_a_stall_inside_the_gripper_workspace_reapproaches_while_it_can() -> None:
    # Stuck 5 mm short of the berry (inside the gripper's 1 cm, outside stall_progress):
    # another axis first; the grasp on the limit only on the last attempt.
    rig, planner = _rig([SQUARE], only_at=BERRIES[1], short=0.005)
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and len(planner.avoided) == 2
    assert result.position_error_mm <= 1.0
    assert not any(r["kind"] == "limit_grasp" for r in rig.machine.log.records)

    config = HarvestConfig(marker_timeout=0.5, stall_time=1.0, reapproaches=0)
    rig, planner = _rig([SQUARE], config, only_at=BERRIES[1], short=0.005)
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and len(planner.avoided) == 1
    assert 2.0 < result.position_error_mm <= 5.0
    assert any(r["kind"] == "limit_grasp" for r in rig.machine.log.records)


def test_the_end_of_the_fine_budget_far_from_the_berry_reapproaches_while_it_can() -> None:
    # Held 5 mm short without saturating (a slow creep): at the budget, another axis.
    config = HarvestConfig(marker_timeout=0.5, stall_time=1.0, fine_budget=2.0)
    rig, planner = _rig([SQUARE], config, only_at=BERRIES[1], short=0.005)
    rig.machine.servo.controller.saturated = False
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and len(planner.avoided) == 2
    assert result.position_error_mm <= 1.0
    why = [r["why"] for r in rig.machine.log.records if r["kind"] == "transition"]
    assert any("after the 2 s budget" in w for w in why)

    config = HarvestConfig(marker_timeout=0.5, stall_time=1.0, fine_budget=2.0, reapproaches=0)
    rig, planner = _rig([SQUARE], config, only_at=BERRIES[1], short=0.005)
    rig.machine.servo.controller.saturated = False
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and len(planner.avoided) == 1
    assert 2.0 < result.position_error_mm <= 5.0
    assert any(r["kind"] == "fine_budget" for r in rig.machine.log.records)


def test_a_stall_within_stall_progress_grasps_without_a_reapproach() -> None:
    rig, planner = _rig([SQUARE], only_at=BERRIES[1], short=0.0015)
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and len(planner.avoided) == 1
    assert any(r["kind"] == "limit_grasp" for r in rig.machine.log.records)


def test_with_no_reapproaches_the_first_stall_is_unreachable() -> None:
    config = HarvestConfig(marker_timeout=0.5, stall_time=1.0, reapproaches=0)
    rig, planner = _rig([SQUARE], config)
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.UNREACHABLE
    assert rig.transitions(1) == [S.IDLE, S.INITIAL_PLACEMENT, S.RETURN_HOME, S.FAULT]
    assert len(planner.avoided) == 1 and rig.vented()


def test_a_stall_on_every_planned_axis_faults_unreachable_after_the_reapproaches() -> None:
    rig, planner = _rig([SQUARE, TILTED])
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.UNREACHABLE
    assert FaultReason.UNREACHABLE not in FAULTS_THAT_STOP  # the run goes on
    assert rig.transitions(1) == [
        S.IDLE, S.INITIAL_PLACEMENT, S.RETURN_HOME, S.INITIAL_PLACEMENT, S.RETURN_HOME,
        S.FAULT,
    ]  # fmt: skip
    assert len(planner.avoided) == 2 and rig.vented()


def test_no_axis_left_to_try_is_unreachable() -> None:
    rig, planner = _rig([SQUARE])
    planner.axes = [SQUARE]  # the cone holds nothing else
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.UNREACHABLE
    fault = next(r for r in rig.machine.log.records if r["kind"] == "fault")
    assert fault["detail"] == "no pre-grasp pose in the approach cone"
    assert rig.vented()


def test_no_other_axis_after_a_graspable_stall_comes_back_to_it() -> None:
    # The square axis ends 4 mm short in fine positioning (inside the gripper's 1 cm) and
    # the cone holds no other axis: the arm comes back along the square plan and grasps
    # where it ends, as after a last stall (this berry was UNREACHABLE before; traced on
    # bush 823 of the rendered world).
    rig, planner = _rig([SQUARE], only_at=BERRIES[1], short=0.004)
    planner.axes = [SQUARE]
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and result.fault is None
    assert np.allclose(rig.machine.axis, SQUARE) and len(planner.avoided) == 2
    assert 2.0 < result.position_error_mm <= 5.0
    back = next(r for r in rig.machine.log.records if r["kind"] == "no_other_axis")
    assert 3.0 < back["back_to_mm"] <= 5.0
    assert rig.transitions(1).count(S.INITIAL_PLACEMENT) == 2


def test_a_last_axis_that_ends_farther_out_comes_back_to_the_nearest_attempt() -> None:
    # Square stalls 4 mm short in fine positioning, the tilted axis 8 mm: both inside the
    # gripper's 1 cm. The arm comes back along the square plan (no new plan) and grasps.
    rig, planner = _rig([SQUARE, TILTED], only_at=BERRIES[1], short=[0.004, 0.008])
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and result.fault is None
    assert rig.transitions(1) == [
        S.IDLE, S.INITIAL_PLACEMENT, S.FINE_POSITIONING, S.RETURN_HOME,
        S.INITIAL_PLACEMENT, S.FINE_POSITIONING, S.RETURN_HOME,
        S.INITIAL_PLACEMENT, S.FINE_POSITIONING, S.GRASP, S.RETURN_HOME, S.DONE,
    ]  # fmt: skip
    assert len(planner.avoided) == 2  # the third attempt reuses the first plan
    assert np.allclose(rig.machine.axis, SQUARE)
    assert 2.0 < result.position_error_mm <= 5.0
    why = [r["why"] for r in rig.machine.log.records if r["kind"] == "transition"]
    assert any(w.startswith("back to the nearest attempt: fine_positioning") for w in why)
    assert any(w.startswith("back to the axis that ended 3.") for w in why)
    assert [v.reason for v in rig.bank.vent_log] == ["startup"]


def test_a_last_axis_that_ends_nearer_grasps_there() -> None:
    rig, planner = _rig([SQUARE, TILTED], only_at=BERRIES[1], short=[0.008, 0.004])
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and len(planner.avoided) == 2
    assert np.allclose(rig.machine.axis, TILTED)
    assert 2.0 < result.position_error_mm <= 5.0
    assert rig.transitions(1).count(S.INITIAL_PLACEMENT) == 2


def test_a_last_axis_that_stalls_in_placement_comes_back_to_a_graspable_attempt() -> None:
    # Before the memory of attempts this berry was UNREACHABLE: the square axis ended
    # 4 mm off in fine positioning (graspable), the tilted one stalled in placement.
    rig, planner = _rig([SQUARE, TILTED], only_at=[BERRIES[1], None], short=[0.004, 0.0])
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and result.fault is None
    assert np.allclose(rig.machine.axis, SQUARE) and len(planner.avoided) == 2
    assert 2.0 < result.position_error_mm <= 5.0
    assert rig.transitions(1).count(S.INITIAL_PLACEMENT) == 3


def test_without_a_graspable_attempt_the_last_stall_is_unreachable() -> None:
    # The square axis stalled 2 cm off (outside the gripper's reach): nothing to come back to.
    rig, _ = _rig([SQUARE, TILTED], only_at=[BERRIES[1], None], short=[0.02, 0.0])
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.UNREACHABLE
    assert rig.transitions(1).count(S.INITIAL_PLACEMENT) == 2 and rig.vented()
