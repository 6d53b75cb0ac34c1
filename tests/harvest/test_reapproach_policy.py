"""The re-approach policy alone (softarm.harvest.machine.reapproach): what follows a
stall, and how near each attempt must end to grasp."""

from __future__ import annotations

import numpy as np

from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.reapproach import Reapproach
from softarm.harvest.machine.states import FaultReason

A, B, C = np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])


def _stall(error: float) -> Fault:
    return Fault(FaultReason.UNREACHABLE, "stalled", retreat_from=np.zeros(9), grasp_error=error)


def _policy(reapproaches: int = 1, planner: bool = True) -> Reapproach:
    return Reapproach(
        reapproaches, stall_progress=0.0005, grasp_workspace=0.01, has_planner=planner
    )


def test_a_stall_with_axes_left_tries_another() -> None:
    p = _policy()
    assert p.more() and p.grasp_within() == 0.0005
    assert p.after(_stall(0.004), A, ()) == "re-approach"
    assert p.nearest is not None and p.nearest.grasp_error == 0.004
    assert p.again(A) == "re-approach 1: another axis" and len(p.tried) == 1


def test_the_last_axis_must_beat_the_nearest_else_it_comes_back() -> None:
    p = _policy()
    p.after(_stall(0.004), A, ())
    p.again(A)
    assert not p.more() and p.grasp_within() == 0.004  # no worse than the nearest
    assert p.after(_stall(0.006), B, ()) == "back to the nearest attempt"
    assert p.back_to is p.nearest and p.back_to is not None
    assert np.array_equal(p.back_to.axis, A)
    assert p.again(B).startswith("back to the axis that ended 4.0 mm off")
    assert p.tried == [A]  # coming back tries no new axis
    assert p.grasp_within() == 0.01  # the attempt come back to grasps in the reach


def test_a_nearer_stall_replaces_the_nearest_and_a_far_one_is_not_kept() -> None:
    p = _policy(reapproaches=3)
    p.after(_stall(0.004), A, ())
    p.after(_stall(0.002), B, ())
    p.after(_stall(0.05), C, ())  # outside the gripper's reach
    assert p.nearest is not None and np.array_equal(p.nearest.axis, B)


def test_other_faults_and_no_planner_end_the_berry() -> None:
    p = _policy()
    timeout = Fault(FaultReason.TIMEOUT, "late", retreat_from=np.zeros(9))
    assert p.after(timeout, A, ()) is None
    lone = _policy(planner=False)
    assert not lone.more() and lone.after(_stall(0.02), A, ()) is None
