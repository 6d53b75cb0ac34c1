"""Fine positioning gives up an approach axis on which the measurement jumps
(:class:`~softarm.harvest.machine.stages.jumps.JumpCounter`, ``servo.FINE_GIVE_UP``): a
converging arm shows no jump; a pose that flips while the arm holds does; in the machine,
a berry whose measured pose flips near it along the square axis is given up there at once
and taken along another axis, where it ran to the 12 s budget before; on the last axis,
or with no other axis to plan, it is worked as before and grasped within reach at the
budget."""

from __future__ import annotations

import numpy as np

from softarm.harvest import BerryTarget, HarvestConfig, HarvestState
from softarm.harvest.machine.stages.jumps import JumpCounter
from softarm.harvest.machine.stages.servo import FINE_GIVE_UP

from .fakes import BERRIES, Rig, make_rig
from .test_reapproach import SQUARE, TILTED, AxisPlanner

S = HarvestState
BERRY = BERRIES[1]


def test_a_converging_arm_shows_no_jump() -> None:
    # The tag world's fine positioning: the error shrinks by a third a step from 5 cm,
    # the arm moving as the model has it, 0.1 mm of noise.
    rng = np.random.default_rng(1)
    counter = JumpCounter()
    direction = np.array([0.6, 0.0, 0.8])
    for k in range(40):
        error = direction * 0.05 * 0.65**k
        counter.see(error + rng.normal(0.0, 1e-4, 3), BERRY + error)
    assert counter.jumps == 0


def test_a_pose_that_flips_away_while_the_arm_holds_is_a_jump() -> None:
    # 0.3 mm off the berry, every third measurement 4 mm out along C1's line of sight.
    counter = JumpCounter()
    still = np.array([0.0003, 0.0, 0.0])
    flip = np.array([0.0, 0.004, 0.0])
    for k in range(12):
        counter.see(still + (flip if k % 3 == 2 else 0.0), BERRY)
    # Four flips out; each flip back, onto the goal, is what the loop could have done.
    assert counter.jumps == 4


def _rig(axes: list[np.ndarray], reapproaches: int = 1) -> Rig:
    """The fake rig with a planner along ``axes``; C1's pose of the arm flips 4 mm along
    y every other frame while the grasp point is within 2 cm of the berry AND the arm
    faces it square (the axis from which C1 sees the cube badly)."""
    config = HarvestConfig(marker_timeout=0.5, stall_time=1.0, reapproaches=reapproaches)
    rig = make_rig(config=config)
    rig.machine.planner = AxisPlanner(axes)
    real_track = rig.tracker.track
    frames = [0]

    def track(time: float) -> np.ndarray | None:
        pose = real_track(time)
        if pose is None:
            return None
        square = float(rig.machine.axis @ SQUARE) > np.cos(np.radians(0.5))
        near = np.linalg.norm(pose[:3, 3] + 0.03 * pose[:3, 2] - BERRY) < 0.02
        frames[0] += 1
        if square and near and frames[0] % 2:
            pose = pose.copy()
            pose[1, 3] += 0.004
        return pose

    rig.tracker.track = track  # type: ignore[method-assign]
    return rig


def _fine_seconds(rig: Rig) -> list[float]:
    """Each fine positioning's duration (s), in order."""
    recs = [r for r in rig.machine.log.records if r["kind"] == "transition"]
    starts = [r["t"] for r in recs if r["new"] == S.FINE_POSITIONING]
    ends = [r["t"] for r in recs if r["old"] == S.FINE_POSITIONING]
    return [b - a for a, b in zip(starts, ends, strict=True)]


def test_a_jumping_axis_is_given_up_for_another() -> None:
    rig = _rig([SQUARE, TILTED])
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and result.fault is None
    assert np.allclose(rig.machine.axis, TILTED)
    assert rig.transitions(1) == [
        S.IDLE, S.INITIAL_PLACEMENT, S.FINE_POSITIONING, S.RETURN_HOME, S.INITIAL_PLACEMENT,
        S.FINE_POSITIONING, S.GRASP, S.RETURN_HOME, S.DONE,
    ]  # fmt: skip
    given_up = next(r for r in rig.machine.log.records if r["kind"] == "jumpy_axis")
    assert given_up["jumps"] == FINE_GIVE_UP
    first, second = _fine_seconds(rig)
    assert first < 2.0 and second < 2.0  # the square axis ran to its 12 s budget before
    assert result.position_error_mm <= 0.5


def test_on_the_last_axis_the_jumps_are_worked_through_as_before() -> None:
    rig = _rig([SQUARE, TILTED], reapproaches=0)
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested
    assert not any(r["kind"] == "jumpy_axis" for r in rig.machine.log.records)
    assert rig.transitions(1).count(S.FINE_POSITIONING) == 1


def test_with_no_other_axis_it_comes_back_to_the_jumping_one() -> None:
    rig = _rig([SQUARE])  # the cone holds nothing else
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested and result.fault is None
    assert any(r["kind"] == "jumpy_axis" for r in rig.machine.log.records)
    back = next(r for r in rig.machine.log.records if r["kind"] == "no_other_axis")
    assert back["back_to_mm"] == 10.0  # the gripper's reach: where a jumping arm may be
    assert rig.transitions(1).count(S.FINE_POSITIONING) == 2
