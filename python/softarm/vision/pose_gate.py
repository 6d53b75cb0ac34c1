"""The jump rule of the cube tracker (:class:`PoseGate`): a tracked position far from where
the arm's own motion puts it is a wrong solution of an ambiguous view, not the arm.

Where the arm may be is the segment from the last accepted position to where its velocity
(from the last two accepted positions) carries it by now: it kept its speed, or slowed,
or stopped (a plan's end, a ramp home the tracker did not watch). A jump is measured
from that segment, not from the last position alone: at the plan's feedforward speed the
gripper moves 2-6 cm a frame, and the rule that measured each jump from the last
position refused one or two frames in three of a fast move, until three in a row agreed,
and the loop following the plan ran blind through them (docs/harvest.md, 'The moves').
The camera is the only witness of the true arm here (the model is a few cm off it, the
commands lead it by the regulators' lag), so the prediction is made from what the camera
saw; a wrong pose is a jump of several cm away from that line.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import NonFiniteError, OutOfRangeError

__all__ = ["PoseGate"]


def _positive(name: str, value: float) -> float:
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise OutOfRangeError(f"{name} = {value!r}: must be finite and > 0")
    return float(value)


class PoseGate:
    """Accepts or refuses each tracked position (m, any fixed frame) at its time (s).

    Args:
        max_jump: a position this far (m) from the predicted one is refused, unless
            ``max_rejects`` in a row were refused: then it is taken as real (the arm was
            moved while unseen) and the prediction starts again from it.
        max_rejects: see ``max_jump``.
        max_speed: the fastest (m/s) the tracked point is believed to move; a faster
            velocity between two accepted positions is scaled down to it, so that one
            wrong position let through (within ``max_jump`` of the prediction) cannot
            carry the prediction far off the arm.
        max_gap: two accepted positions further apart in time (s) than this give no
            velocity (the arm may have stopped, turned, or been moved meanwhile): the
            prediction is then the last position, the rule of a still arm. Two frames
            looked at (:meth:`looked`) further apart than this mean the camera was not
            watched in between (an open-loop ramp home): the next position starts the
            track again, as the first one did.
    """

    def __init__(
        self,
        max_jump: float = 0.03,
        max_rejects: int = 3,
        max_speed: float = 2.0,
        max_gap: float = 0.25,
    ) -> None:
        self.max_jump = _positive("max_jump", max_jump)
        self.max_speed = _positive("max_speed", max_speed)
        self.max_gap = _positive("max_gap", max_gap)
        if isinstance(max_rejects, bool) or not isinstance(max_rejects, int) or max_rejects < 1:
            raise OutOfRangeError(f"max_rejects = {max_rejects!r}: must be an integer >= 1")
        self.max_rejects = max_rejects
        self._last: tuple[float, FloatArray] | None = None
        self._velocity: FloatArray | None = None
        self._rejects = 0
        self._looked: float | None = None

    def looked(self, time: float) -> None:
        """A frame at ``time`` (s) was looked at, whether or not it gave a position. After
        more than ``max_gap`` unwatched the last position says nothing of where the arm
        is: the harvest moves it open loop, unwatched, by tens of cm (the ramp home), and
        measured from there its first poses were refused as a jump until ``max_rejects``
        agreed, two control periods a berry spent waiting (docs/harvest.md).

        Raises:
            NonFiniteError: ``time`` is not finite (as :meth:`accept`).
        """
        if not math.isfinite(time):
            raise NonFiniteError(f"time = {time!r}: must be finite")
        if self._looked is not None and time - self._looked > self.max_gap:
            self._last, self._velocity, self._rejects = None, None, 0
        self._looked = float(time)

    def predicted(self, time: float) -> FloatArray | None:
        """Where the last accepted position and velocity put the point at ``time``; None
        before the first accepted position. Past ``max_gap`` after the last accepted
        position the velocity is not carried on: a move seen no longer has ended (an
        open-loop ramp home is not watched), and where it ended says nothing of it."""
        if self._last is None:
            return None
        t_last, p_last = self._last
        ahead = time - t_last
        if self._velocity is None or not 0.0 <= ahead <= self.max_gap:
            return p_last.copy()
        return p_last + self._velocity * ahead

    def accept(self, time: float, position: npt.ArrayLike) -> bool:
        """Whether ``position`` at ``time`` is the arm; an accepted one becomes the last.

        Raises:
            NonFiniteError: ``time`` or ``position`` is not finite.
        """
        p = np.asarray(position, dtype=np.float64)
        if not (math.isfinite(time) and np.all(np.isfinite(p))):
            raise NonFiniteError(f"position = {p.tolist()!r} at time = {time!r}: must be finite")
        if self._last is not None and self.off_course(time, p) > self.max_jump:
            self._rejects += 1
            if self._rejects < self.max_rejects:
                return False
            self._velocity = None  # the streak agreed: the motion before it says nothing
            self._last = None
        self._rejects = 0
        self._velocity = self._velocity_to(time, p)
        self._last = (float(time), p.copy())
        return True

    def off_course(self, time: float, position: FloatArray) -> float:
        """How far (m) ``position`` is from the way the arm was going: the segment from
        the last accepted position to the predicted one. The arm may have kept its speed
        or stopped (a plan's end, a ramp ended unseen) or anything between, so the whole
        segment is where it may be; a wrong pose is a jump away from it."""
        assert self._last is not None
        start = self._last[1]
        way = self.predicted(time) - start  # type: ignore[operator]
        length2 = float(way @ way)
        along = 0.0 if length2 == 0.0 else float(np.clip((position - start) @ way / length2, 0, 1))
        return float(np.linalg.norm(position - (start + along * way)))

    def _velocity_to(self, time: float, p: FloatArray) -> FloatArray | None:
        """The velocity from the last accepted position to ``p``, at most ``max_speed``;
        None without a last position or when it is older than ``max_gap``."""
        if self._last is None:
            return None
        t_last, p_last = self._last
        dt = time - t_last
        if not 0.0 < dt <= self.max_gap:
            return None
        v = (p - p_last) / dt
        speed = float(np.linalg.norm(v))
        return v if speed <= self.max_speed else v * (self.max_speed / speed)
