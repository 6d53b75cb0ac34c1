"""What one closed-loop stage of :class:`~softarm.harvest.machine.stages.servo.Servo` servos to and
how it may end (:class:`ServoGoal`), where the grasp point is against it each step
(:class:`Aim`), and how the stage has progressed (:class:`Progress`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softarm.harvest.machine.interfaces import FloatArray

__all__ = ["Aim", "Progress", "ServoGoal"]


@dataclass(frozen=True)
class ServoGoal:
    """A closed-loop stage on the berry (see :meth:`Servo._servo
    <softarm.harvest.machine.stages.servo.Servo._servo>`).

    ``distance``: how far short of the berry along the approach axis the end effector
    goes (m); ``tol``: the position tolerance (m); ``timeout``: the stage's time (s).
    ``budget`` (fine positioning): past it, grasp within ``grasp_within`` (m) or be
    UNREACHABLE; ``record_errors``: keep every step's errors at the grasp;
    ``placed_on_limit`` (placement): a saturated arm within ``tol`` hands over;
    ``frozen`` (the way back): the berry is this fixed point, held in the fingers;
    ``ahead`` (placement, the back-out): the stage ends on where the commands already
    sent put the arm once it has caught up (the lag model's motion in flight carried
    through the model), not on where it is measured now: the next stage goes on from
    there while the arm is still on its way (docs/harvest.md, 'The moves');
    ``give_up`` (fine positioning with another axis left to try): after this many jumps
    of the measured grasp error (:class:`~softarm.harvest.machine.stages.jumps.
    JumpCounter`) the axis is given up, UNREACHABLE, to re-approach along another
    (None: never, and the jumps are not counted);
    ``ahead_within`` (m): only once the arm is also measured this near the goal. The
    back-out's: the way home, begun with most of the back-out still in flight, cut the
    corner from the approach line towards home, 6 mm from a cane (diagnosis seed 1347);
    begun within 2 cm of the pre-grasp pose, the corner it cuts is inside the last 2 cm
    of the approach line, which is clear of the canes."""

    distance: float
    tol: float
    timeout: float
    budget: float | None = None
    grasp_within: float = 0.0
    record_errors: bool = True
    placed_on_limit: bool = False
    frozen: FloatArray | None = None
    ahead: bool = False
    ahead_within: float = float("inf")
    give_up: int | None = None


@dataclass(frozen=True)
class Aim:
    """One step's goal pose of the end effector, and the grasp point's position error
    (m) and the pointing error (rad) against it."""

    goal: FloatArray
    error: float
    pointing: float


@dataclass
class Progress:
    """How a stage has gone: steps in a row within tolerance, the best error and when,
    since when the resolver has been saturated (None: it is not), and the last measured
    grasp-point offsets from the goal (m, base frame; oldest first) that fine
    positioning's "confidence" end rule estimates the error from."""

    start: float
    inside: int = 0
    best: float = np.inf
    best_t: float = 0.0
    saturated_since: float | None = None
    offsets: list[FloatArray] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.best_t = self.start

    def update(self, t: float, error: float, saturated: bool, stall_progress: float) -> None:
        """A step at ``t``: a new best when ``error`` beats it by ``stall_progress``."""
        if error < self.best - stall_progress:
            self.best, self.best_t = error, t
        if not saturated:
            self.saturated_since = None
        elif self.saturated_since is None:  # not `or`: a saturation from t = 0.0 is one
            self.saturated_since = t

    def measured(self, offset: FloatArray, window: int) -> bool:
        """Keep ``offset`` among the last ``window`` offsets; False (nothing kept) when it
        repeats the last one exactly: the same camera frames read again are no new
        measurement, and counting them would shrink the standard error for nothing."""
        if self.offsets and np.array_equal(self.offsets[-1], offset):
            return False
        self.offsets.append(np.array(offset, dtype=np.float64))
        del self.offsets[:-window]
        return True

    def stalled(self, t: float, stall_time: float) -> bool:
        """Saturated, and without progress, for longer than ``stall_time``."""
        since = self.saturated_since
        return since is not None and min(t - since, t - self.best_t) > stall_time
