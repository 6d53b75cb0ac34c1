"""The loop on the berry (eq. 21-22): the end effector driven along the approach axis to
a :class:`~softarm.harvest.machine.stages.goal.ServoGoal` short of the berry, one resolver
step a period, until one of the stage's end rules (:mod:`.end_rules`) ends it. Placement,
fine positioning and the back-out of the way home are this loop with different goals."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from softarm.errors import NonFiniteError
from softarm.harvest.machine.interfaces import BerryFix, FloatArray, Observation
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Fault, StageOutcome
from softarm.harvest.machine.stages.arm_link import ArmLink
from softarm.harvest.machine.stages.end_rules import (
    jumpy,
    lost_near,
    settled_or_out_of_time,
    stalled,
)
from softarm.harvest.machine.stages.goal import Aim, Progress, ServoGoal
from softarm.harvest.machine.stages.jumps import JumpCounter
from softarm.harvest.machine.stages.play_skip import PlaySkip
from softarm.harvest.machine.states import HarvestState
from softarm.harvest.machine.targets import grasp_point, pointing_error, tool_pose

__all__ = ["BerryLoop"]


class BerryLoop:
    """Runs a :class:`ServoGoal` on the shared :class:`ArmLink`."""

    def __init__(self, link: ArmLink) -> None:
        self.link = link

    def run(
        self, watch: BerryWatch, stage: HarvestState, q: FloatArray, axis: FloatArray,
        goal: ServoGoal,
    ) -> StageOutcome:  # fmt: skip
        """Drive the end effector to ``goal.distance`` short of the berry along the
        approach ``axis`` until the error stays below ``goal.tol``; see
        :class:`HarvestConfig` and :class:`ServoGoal` for how else it may end."""
        start = self.link.clock.now()
        watch.excuse_berry(start)  # the open-loop ramp needed no berry
        progress = Progress(start)
        jumps = None if goal.give_up is None else JumpCounter()
        skip = self._play_skip(stage)
        last: Aim | None = None  # this stage's last measured aim
        while True:
            try:
                seen = self.link.look(watch, q, need_fix=goal.frozen is None)
            except Fault as fault:
                return lost_near(self.link, fault, q, axis, last, goal)
            if goal.frozen is not None:
                seen = replace(seen, fix=BerryFix(goal.frozen, "held", seen.t - start))
            if seen.pose is None or seen.fix is None:
                watch.log_step(stage, seen, q, None, None, False)
                q = self.link.hold(q)
                continue
            aim = last = self._aim(seen, axis, goal.distance)
            if goal.record_errors:  # the errors at the grasp
                watch.record_grasp_errors(self._grasp_error(seen), aim.pointing)
            ended = settled_or_out_of_time(
                self.link, watch, stage, seen, q, axis, self._ahead(seen, axis, goal, aim),
                goal, progress,
            )  # fmt: skip
            if ended is not None:
                return ended
            if jumps is not None:
                self._count_jump(jumps, seen, aim, axis, goal.distance, skip is not None)
                jumpy(self.link, stage, seen, q, aim, jumps.jumps, goal)
            q_next, saturated = self._loop_step(q, aim.goal, seen.pose)
            if skip is not None:
                q_next = self._skip_play(skip, q, q_next, seen.t)
            progress.update(seen.t, aim.error, saturated, self.link.cfg.stall_progress)
            if progress.stalled(seen.t, self.link.cfg.stall_time):
                return stalled(self.link, stage, seen, q, axis, aim, goal)
            watch.log_step(stage, seen, q_next, aim.goal, (aim.error, aim.pointing), saturated)
            q = self.link.hold(q_next)  # goes on from what was sent

    def _play_skip(self, stage: HarvestState) -> PlaySkip | None:
        """Fine positioning's :class:`PlaySkip` with ``[harvest] play_skip`` set."""
        periods = self.link.cfg.play_skip
        return PlaySkip(periods) if periods and stage is HarvestState.FINE_POSITIONING else None

    def _skip_play(self, skip: PlaySkip, q: FloatArray, q_next: FloatArray, t: float) -> FloatArray:
        """``q_next`` with the channels creeping through the play moved to its edge (logged
        as ``play_skip``)."""
        moved, channels = skip.step(q, q_next, self.link.actuator.play_band())
        if channels:
            self.link.log.event("play_skip", t=t, channels=channels)
        return moved

    def _aim(self, seen: Observation, axis: FloatArray, distance: float) -> Aim:
        """The grasp point, not the end-effector origin, is servoed onto its goal
        ``distance - grasp_offset`` short of the berry: a residual pointing error then
        does not move the berry off the fingers."""
        assert seen.pose is not None and seen.fix is not None
        offset = self.link.cfg.grasp_offset
        point = seen.fix.position - (distance - offset) * axis
        goal = tool_pose(seen.pose, point, axis, offset)
        error = float(np.linalg.norm(grasp_point(seen.pose, offset) - point))
        return Aim(goal, error, pointing_error(seen.pose, axis))

    def _count_jump(
        self, jumps: JumpCounter, seen: Observation, aim: Aim, axis: FloatArray, distance: float,
        through_play: bool = False,
    ) -> None:  # fmt: skip
        """Give ``jumps`` this step's measured offset of the grasp point from its goal and
        where the model puts the grasp point at the lag model's q (the q sent less the
        motion in flight; ``through_play``: the lag model's play output, where the
        regulators' pressure is not yet the arm's: a command moved across the band by
        :class:`PlaySkip` moves the pressure, not the arm); a jump is logged
        (``measurement_jump``)."""
        assert seen.pose is not None and seen.fix is not None
        offset = self.link.cfg.grasp_offset
        point = seen.fix.position - (distance - offset) * axis
        flight = self.link.actuator.in_flight()
        q_arm = self.link.actuator.sent - (0.0 if flight is None else flight)
        band = self.link.actuator.play_band() if through_play else None
        if band is not None:
            q_arm = band[0]
        model = grasp_point(self.link.controller.model_pose(q_arm), offset)
        before = jumps.jumps
        residual = jumps.see(grasp_point(seen.pose, offset) - point, model)
        if jumps.jumps > before:
            self.link.log.event("measurement_jump", t=seen.t, residual_m=residual, error=aim.error)

    def _ahead(self, seen: Observation, axis: FloatArray, goal: ServoGoal, aim: Aim) -> Aim:
        """The aim a stage with ``goal.ahead`` ends on: the measured pose carried by the
        model's motion from where the lag model has the arm now (the q sent less the
        motion still in flight) to the q sent, i.e. where the commands already sent put
        the arm. On a slow plant the arm trails the loop's last command by seconds,
        most of it the regulators' lag with a channel near 0 or 70 psi: the loop's
        commands have stopped changing long before the measured pose is within the
        tolerances. Without ``goal.ahead`` or a lag model, or with the arm measured
        farther than ``goal.ahead_within`` from the goal, ``aim`` itself."""
        flight = self.link.actuator.in_flight()
        if not goal.ahead or flight is None or seen.pose is None:
            return aim
        if aim.error > goal.ahead_within:
            return aim
        sent = self.link.actuator.sent
        model_pose = self.link.controller.model_pose
        # The model's motion still to come, in the end effector's frame: the true arm's
        # is a few per cent off it, so the measured pose carries the model's error.
        shift = np.linalg.solve(model_pose(sent - flight), model_pose(sent))
        return self._aim(replace(seen, pose=seen.pose @ shift), axis, goal.distance)

    def _grasp_error(self, seen: Observation) -> float:
        """The grasp point's distance (m) from the berry."""
        assert seen.pose is not None and seen.fix is not None
        return float(
            np.linalg.norm(grasp_point(seen.pose, self.link.cfg.grasp_offset) - seen.fix.position)
        )

    def _loop_step(
        self, q: FloatArray, goal: FloatArray, pose: FloatArray
    ) -> tuple[FloatArray, bool]:
        """The resolver's next command towards ``goal`` from the measured ``pose``."""
        q_next, saturated = self.link.controller.step(q, goal, pose)
        q_next = np.asarray(q_next, dtype=np.float64)
        if not np.all(np.isfinite(q_next)):
            raise NonFiniteError(f"controller returned q = {q_next.tolist()!r}")
        return q_next, saturated
