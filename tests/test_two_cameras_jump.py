"""The cube tracker's jump rule (softarm.vision.pose_gate.PoseGate, used by
CameraVision): a fast move of the arm is followed, a wrong pose is still refused."""

from __future__ import annotations

import math

import numpy as np
import pytest

from softarm.errors import NonFiniteError, OutOfRangeError
from softarm.vision.pose_gate import PoseGate

PERIOD = 0.05
SPEED = 1.0  # m/s: 5 cm a frame, a plan's feedforward on the nominal plant


def _moving(gate: PoseGate, frames: int) -> tuple[float, np.ndarray]:
    """Feed ``frames`` positions of a point starting from rest along +x, 2 cm a frame
    more each frame up to ``SPEED``; each must be accepted. Returns the last time and
    position."""
    t, p = 0.0, np.zeros(3)
    for k in range(frames):
        step = min(SPEED * PERIOD, 0.02 * k)
        t, p = k * PERIOD, p + np.array([step, 0.0, 0.0])
        assert gate.accept(t, p), f"frame {k} of a steady move refused"
    return t, p


def test_a_fast_move_is_followed_frame_by_frame() -> None:
    """5 cm a frame, farther than max_jump (3 cm) from the last pose: the rule that
    measured jumps from the last pose refused two frames in three of such a move."""
    gate = PoseGate(max_jump=0.03)
    _moving(gate, 12)


def test_the_old_rule_would_refuse_the_same_move() -> None:
    """The same move against a still prediction (no velocity yet): the second frame,
    5 cm from the first, is refused; the fix is the velocity, not a looser threshold."""
    gate = PoseGate(max_jump=0.03)
    assert gate.accept(0.0, np.zeros(3))
    assert not gate.accept(PERIOD, np.array([0.05, 0.0, 0.0]))


def test_a_wrong_pose_off_the_line_of_motion_is_refused() -> None:
    """During the move, a pose 5 cm to the side of where the arm is going (a wrong
    solution of an ambiguous view) is refused, and the next true pose is accepted."""
    gate = PoseGate(max_jump=0.03)
    t, p = _moving(gate, 6)
    t += PERIOD
    truth = p + np.array([SPEED * PERIOD, 0.0, 0.0])
    assert not gate.accept(t, truth + np.array([0.0, 0.05, 0.0]))
    t += PERIOD
    assert gate.accept(t, truth + np.array([SPEED * PERIOD, 0.0, 0.0]))


def test_a_wrong_pose_ahead_of_the_motion_is_refused() -> None:
    """A pose 5 cm beyond where the arm's speed can carry it is refused too."""
    gate = PoseGate(max_jump=0.03)
    t, p = _moving(gate, 6)
    assert not gate.accept(t + PERIOD, p + np.array([SPEED * PERIOD + 0.05, 0.0, 0.0]))


def test_a_wrong_pose_of_a_still_arm_is_refused() -> None:
    gate = PoseGate(max_jump=0.03)
    for k in range(4):
        assert gate.accept(k * PERIOD, np.zeros(3))
    assert not gate.accept(4 * PERIOD, np.array([0.0, 0.0, 0.04]))
    assert gate.accept(5 * PERIOD, np.zeros(3))


def test_an_arm_that_stopped_is_accepted() -> None:
    """The arm was moving fast and stopped (a plan's end, a ramp home not watched): a
    pose where it stopped, behind the prediction, is on the way it was going."""
    gate = PoseGate(max_jump=0.03)
    t, p = _moving(gate, 6)
    assert gate.accept(t + 3 * PERIOD, p + np.array([0.01, 0.0, 0.0]))


def test_a_streak_of_agreeing_poses_is_taken_as_real() -> None:
    """``max_rejects`` poses in a row far from the way: the arm was moved (unseen)."""
    gate = PoseGate(max_jump=0.03, max_rejects=3)
    assert gate.accept(0.0, np.zeros(3))
    moved = np.array([0.2, 0.0, 0.0])
    assert not gate.accept(PERIOD, moved)
    assert not gate.accept(2 * PERIOD, moved)
    assert gate.accept(3 * PERIOD, moved)
    assert gate.accept(4 * PERIOD, moved)  # from there on the new place is the last


def test_one_wrong_pose_let_through_does_not_carry_the_prediction_away() -> None:
    """A wrong pose 2.5 cm off (within max_jump, so accepted) gives a velocity; the
    velocity is bounded by max_speed, so the next true pose of a still arm is kept."""
    gate = PoseGate(max_jump=0.03, max_speed=0.3)
    for k in range(3):
        assert gate.accept(k * PERIOD, np.zeros(3))
    assert gate.accept(3 * PERIOD, np.array([0.025, 0.0, 0.0]))
    assert gate.accept(4 * PERIOD, np.zeros(3))


def test_the_velocity_is_not_carried_past_max_gap() -> None:
    """Seen again long after, the arm is looked for where it was last seen."""
    gate = PoseGate(max_jump=0.03, max_gap=0.25)
    t, p = _moving(gate, 6)
    assert np.allclose(gate.predicted(t + 1.0), p)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"max_jump": 0.0}, "max_jump"),
        ({"max_jump": math.nan}, "max_jump"),
        ({"max_speed": -1.0}, "max_speed"),
        ({"max_gap": math.inf}, "max_gap"),
        ({"max_rejects": 0}, "max_rejects"),
        ({"max_rejects": True}, "max_rejects"),
    ],
)
def test_bad_settings_name_themselves(kwargs: dict[str, float], name: str) -> None:
    with pytest.raises(OutOfRangeError, match=name):
        PoseGate(**kwargs)  # type: ignore[arg-type]


def test_a_non_finite_pose_is_an_error() -> None:
    gate = PoseGate()
    with pytest.raises(NonFiniteError, match="position"):
        gate.accept(0.0, np.array([0.0, math.nan, 0.0]))


def test_after_a_stretch_unwatched_the_first_pose_starts_the_track_again() -> None:
    """Frames looked at more than ``max_gap`` apart: the arm was moved unwatched (the
    ramp home), and its first pose, 20 cm from the last one, is taken at once."""
    gate = PoseGate(max_jump=0.03, max_gap=0.25)
    for k in range(3):
        gate.looked(k * PERIOD)
        assert gate.accept(k * PERIOD, np.zeros(3))
    t = 2 * PERIOD + 1.0
    gate.looked(t)
    assert gate.accept(t, np.array([0.2, 0.0, 0.0]))
    gate.looked(t + PERIOD)
    assert not gate.accept(t + PERIOD, np.array([0.2, 0.05, 0.0]))  # watched: gated again


def test_frames_watched_without_a_pose_keep_the_gate() -> None:
    """Frames looked at every period that gave no pose (the cube hidden): the arm was
    watched, and a pose 20 cm off is still a jump."""
    gate = PoseGate(max_jump=0.03, max_gap=0.25)
    gate.looked(0.0)
    assert gate.accept(0.0, np.zeros(3))
    for k in range(1, 21):
        gate.looked(k * PERIOD)
    assert not gate.accept(20 * PERIOD, np.array([0.2, 0.0, 0.0]))


def test_a_non_finite_time_looked_at_is_an_error() -> None:
    with pytest.raises(NonFiniteError, match="time"):
        PoseGate().looked(math.nan)
