"""The closed loops inside the harvesting states: wait for the markers, place, fine
position, go home. Each step reads the cameras, checks them, logs, and commands the arm.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from softarm.errors import NonFiniteError, ParameterError
from softarm.harvest.interfaces import (
    BerryFix,
    Clock,
    Controller,
    FloatArray,
    Observation,
    PlacementPlanner,
    PressureActuator,
    require_controller,
)
from softarm.harvest.log import HarvestLog
from softarm.harvest.observe import BerryWatch
from softarm.harvest.outcome import Ending, Fault, StageOutcome
from softarm.harvest.servo_goal import Aim, Progress, ServoGoal
from softarm.harvest.states import FaultReason, HarvestState
from softarm.harvest.targets import grasp_point, pointing_error, tool_pose
from softarm.harvest_config import HarvestConfig

__all__ = ["Fault", "Servo"]


#: How much nearer (m) to a cane than the arm is the way to a command may come, where the
#: arm is already inside ``transport_margin`` (:meth:`Servo._clear_way`): about what one
#: period's step of the loop changes the gap by, so the loop is slowed there, not locked.
WAY_SLACK = 0.001

#: The most (m) the q the safety layer returns differs from the q commanded by rounding
#: alone (m -> psi -> m, about 1e-18): far below what any regulator resolves, far below
#: what a clamp or a rate limit takes off.
SEND_ROUNDING = 1e-12


def straight_step(q: FloatArray, goal: FloatArray, step: float) -> FloatArray:
    """The move (m) from ``q`` towards ``goal`` this period: along the straight line in
    actuator space, the fastest channel at ``step``. The planner checks the canes along
    that line; clipped channel by channel, the channels with the least to go would
    arrive first and the arm would leave the line it was checked along."""
    d = np.asarray(goal, dtype=np.float64) - q
    most = float(np.max(np.abs(d), initial=0.0))
    return d if most <= step else d * (step / most)


class Servo:
    """Runs the stages of :class:`~softarm.harvest.machine.HarvestMachine`.

    It keeps no state of a berry or of the machine: each stage is told the berry's
    :class:`~softarm.harvest.observe.BerryWatch`, the ``stage`` it runs as (for the step
    log and the fault messages) and what it works towards, and returns where it ended.
    """

    def __init__(
        self,
        clock: Clock,
        controller: Controller,
        actuator: PressureActuator,
        config: HarvestConfig,
        log: HarvestLog,
    ) -> None:
        self.clock, self.actuator = clock, actuator
        self.controller = require_controller(controller)
        self.cfg, self.log = config, log

    # -- stages ---------------------------------------------------------------------

    def wait_visible(self, watch: BerryWatch, stage: HarvestState, q: FloatArray) -> None:
        """IDLE: hold the arm until both the cube and the berry are seen."""
        watch.restart()
        while True:
            seen = watch.observe()
            watch.log_step(stage, seen, q, None, None, False)
            if seen.pose is not None and seen.fix is not None:
                return
            q = self._hold(q)

    def plan(
        self,
        watch: BerryWatch,
        q: FloatArray,
        planner: PlacementPlanner,
        avoid: Sequence[FloatArray] = (),
    ) -> tuple[tuple[FloatArray, ...], FloatArray]:
        """INITIAL_PLACEMENT, first: solve the pre-grasp pose (and the approach axis,
        inside the allowed cone, none of ``avoid``) on the model, holding ``q`` until the
        cube and the berry are seen. Returns the plan's waypoints and its axis; no plan
        is UNREACHABLE."""
        seen = watch.observe()
        while seen.pose is None or seen.fix is None:
            q = self._hold(q)
            seen = watch.observe()
        plan = planner.plan(q, seen.fix.position, seen.pose, avoid)
        if plan is None:
            raise Fault(FaultReason.UNREACHABLE, "no pre-grasp pose in the approach cone")
        planned, axis = plan
        self.log.event(
            "plan", t=seen.t, q=planned, axis=axis, berry=seen.fix.position,
            fell_back=bool(getattr(planner, "fell_back", False)),
        )  # fmt: skip
        return tuple(planned), axis

    def place(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        axis: FloatArray,
        waypoints: tuple[FloatArray, ...] = (),
    ) -> StageOutcome:
        """INITIAL_PLACEMENT: to the pre-grasp pose, ``standoff`` short of the grasp pose,
        approaching along ``axis``.

        A plan's ``waypoints`` (:meth:`plan`) are first followed in closed loop
        (:meth:`follow`, the canes repelling inside the resolver), then the loop closes
        on the berry (eq. 22) to remove the model's error. The outcome carries the axis
        and the waypoints used."""
        c = self.cfg
        start = self.clock.now()
        for q_way in waypoints:
            q = self.follow(watch, stage, q, q_way, start + c.placement_timeout)
        placement = ServoGoal(
            c.grasp_offset + c.standoff, c.placement_tolerance, c.placement_timeout,
            placed_on_limit=True,
        )  # fmt: skip
        out = self._servo(watch, stage, q, axis, placement)
        return replace(out, waypoints=waypoints)

    def fine(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        axis: FloatArray,
        grasp_within: float | None = None,
    ) -> StageOutcome:
        """FINE_POSITIONING: grasp point onto the berry (eye-in-hand, eq. 21).

        Saturated on a joint limit without progress, or past ``fine_budget``, it grasps
        inside the gripper's ±1 cm (III-D), or only within ``grasp_within`` (m) when the
        machine has a better use for the arm (another axis to try, an earlier attempt
        that ended nearer): farther out it is UNREACHABLE here, with the error."""
        c = self.cfg
        within = c.grasp_workspace if grasp_within is None else grasp_within
        fine = ServoGoal(c.grasp_offset, c.fine_tolerance, c.fine_timeout, c.fine_budget, within)
        return self._servo(watch, stage, q, axis, fine)

    def go_home(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        home: FloatArray,
        axis: FloatArray,
        waypoints: tuple[FloatArray, ...],
        berry: FloatArray | None,
    ) -> FloatArray:
        """RETURN_HOME: back out to the pre-grasp pose (the approach line is free of
        branches) of the ``berry`` last seen, along ``axis``, ramp back through the
        placement plan's ``waypoints``, then to ``home``."""
        c = self.cfg
        start = self.clock.now()
        try:
            back_out = ServoGoal(
                c.grasp_offset + c.standoff, c.placement_tolerance, c.home_timeout / 2,
                record_errors=False, frozen=berry,
            )  # fmt: skip
            q = self._servo(watch, stage, q, axis, back_out).q
        except Fault as fault:
            # Backing out is best effort: the berry is already in the fingers (or the
            # machine is backing out of a fault), and the ramp home is open loop anyway.
            # With the cube lost it is the only way out: vented in the bush, the arm
            # would relax to its rest shape through the canes.
            if fault.reason not in (
                FaultReason.TIMEOUT,
                FaultReason.UNREACHABLE,
                FaultReason.MARKER_LOST,
            ):
                raise
            self.log.event("retreat_incomplete", t=self.clock.now(), detail=str(fault))
            if fault.retreat_from is not None:  # where the loop left the arm
                q = fault.retreat_from
        return self._way_back(watch, stage, q, (*reversed(waypoints), home), start)

    def _way_back(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        way: Sequence[FloatArray],
        start: float,
    ) -> FloatArray:
        """Leave by the planned way in, reversed, then home (the last of ``way``),
        closed on the tracked cube as the way in was (:meth:`follow`: the canes repel
        inside the resolver's step, the way to each command is checked): the model may be
        centimetres off the true arm (a rod sagging under gravity), and a ramp open loop
        through the model's waypoints would carry the true arm wherever that error puts
        it. The loop ends on the exact home q, open loop from where it left the arm. If
        the cube is lost or the loop runs out of ``home_timeout``, the rest of the way is
        ramped open loop (the only way out: vented in the bush, the arm would relax
        through the canes)."""
        c = self.cfg
        legs = list(way)
        try:
            while legs:
                q = self.follow(watch, stage, q, legs[0], start + c.home_timeout)
                legs.pop(0)
        except Fault as fault:
            if fault.reason not in (FaultReason.TIMEOUT, FaultReason.MARKER_LOST):
                raise
            self.log.event("return_open_loop", t=self.clock.now(), detail=str(fault))
            q = fault.retreat_from if fault.retreat_from is not None else q
            for q_way in legs[:-1]:
                q = self.ramp(watch, stage, q, q_way, self.clock.now() + c.home_timeout)
        home = way[-1]
        return self.ramp(watch, stage, q, home, self.clock.now() + c.home_timeout)

    def follow(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        q_way: FloatArray,
        deadline: float,
    ) -> FloatArray:
        """Follow the planned segment ``q`` → ``q_way`` in closed loop on the eye-to-hand
        camera until the end effector is within ``placement_tolerance`` of the model's pose
        at ``q_way``.

        Each period the plan's elongations advance by ``home_speed`` (the feedforward of the
        planned q) and the resolver's step, closed on the measured pose towards the model's
        pose at the plan's current point, adds the correction: the model's error is taken
        out as the arm goes and the known canes repel it inside the step (planning paper
        eq. 9), where an open-loop ramp would carry the true arm, a few cm off the model,
        into a cane. The resolver alone is local: closed on a waypoint 20-30 cm away it
        saturates on the joint limits, which is why the plan's q leads."""
        c = self.cfg
        model_pose = self.controller.model_pose
        lower, upper = self.controller.limits()
        step = c.home_speed * c.period
        nominal = np.asarray(q, dtype=np.float64).copy()  # the plan's point now
        goal_final = model_pose(q_way)
        best, best_t = np.inf, self.clock.now()
        held = False
        while True:
            seen = self._look(watch, q, need_fix=False)
            if seen.pose is None:
                watch.log_step(stage, seen, q, None, None, False)
                q = self._hold(q)
                continue
            on_plan_end = bool(np.all(nominal == q_way))
            err = float(np.linalg.norm(seen.pose[:3, 3] - goal_final[:3, 3]))
            if on_plan_end and err <= c.placement_tolerance:
                return q
            if on_plan_end and self.actuator.in_flight() is not None and self._arrived():
                # The plan is done and the arm has caught up with it (lag model): what is
                # left is the model's error, which the lag-bounded correction here takes
                # out at a few per cent a period on a slow plant. The loop on the berry
                # that follows takes it out at the predictor's full gain.
                self.log.event("waypoint_handover", t=seen.t, error=err)
                return q
            if err < best - c.stall_progress:
                best, best_t = err, seen.t
            elif on_plan_end and seen.t - best_t > c.stall_time:
                # The true arm cannot reach the model's pose of this waypoint (a limit, a
                # cane's repulsion): it is only a waypoint, the loop on the berry follows.
                self.log.event("waypoint_stalled", t=seen.t, error=err)
                return q
            if seen.t > deadline:
                raise Fault(
                    FaultReason.TIMEOUT,
                    f"{stage.value}: waypoint not reached, error {err:.4f} m",
                    retreat_from=q,
                )
            goal = model_pose(nominal)
            q_fb, saturated = self.controller.follow_step(q, goal, seen.pose)
            advance = straight_step(nominal, q_way, step)
            # Feedforward of the plan's motion on top of the closed-loop correction, kept
            # inside the limits the resolver's own command respects.
            q_next = np.clip(np.asarray(q_fb, dtype=np.float64) + advance, lower, upper)
            if not np.all(np.isfinite(q_next)):
                raise NonFiniteError(f"controller returned q = {q_next.tolist()!r}")
            q_next = self._clear_way(q, (q_next, np.clip(q + advance, lower, upper)))
            if q_next is q:  # held: the plan waits for the arm
                if not held:
                    self.log.event("transport_held", t=seen.t, error=err)
                held = True
            else:
                held = False
                nominal = nominal + advance
            watch.log_step(
                stage, seen, q_next, goal, (err, pointing_error(seen.pose, goal[:3, 2])), saturated
            )
            # Go on from what was sent: the safety layer may have clamped or rate-limited it.
            q = self.actuator.send(q_next)
            self.clock.sleep(c.period)

    def _clear_way(self, q: FloatArray, candidates: Sequence[FloatArray]) -> FloatArray:
        """The first of the ``candidates`` commands whose way keeps clear of the canes on
        the model, else ``q`` (the last command, held).

        The way is the straight line in actuator space from where the lag model has the
        arm now (``q`` less the motion still in flight) to the candidate: regulators
        with one first-order lag move the elongations straight towards a held command.
        It is clear when it stays ``transport_margin`` from the canes or, where the arm
        is already nearer than that (a berry by a cane; the model's gap there is a few
        mm to a few cm off the true one), when it comes no more than ``WAY_SLACK``
        nearer than the arm is: inside the margin the loop may close in on a cane only
        slowly. A command is checked on its own, but the arm, a whole lag behind it,
        cuts across from where it is to where the command has gone: on seed 504 without
        calibration the placement loop's correction piled up while the arm trailed, and
        the arm crossed a cane between two clear commands (docs/harvest.md). Holding
        ``q`` keeps the arm on the line checked the period before."""
        flight = self.actuator.in_flight()
        arm_q = q if flight is None else q - flight
        for candidate in candidates:
            gaps = self.controller.way_gaps(arm_q, candidate)
            if gaps is None:
                return candidate
            need = min(self.cfg.transport_margin, gaps[0] - WAY_SLACK)
            if float(np.min(gaps)) >= need:
                return candidate
        return q

    def ramp(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        goal: FloatArray,
        deadline: float,
        observe: bool = False,
        settle: bool = True,
    ) -> FloatArray:
        """Move the elongations straight to ``goal`` at ``home_speed``, open loop; with
        ``observe`` the cameras are still read (and checked) at every step; with
        ``settle`` (the default) return only once the lag model has the arm there.

        Every ramp is bounded in time: past ``deadline`` (clock time, finite) it is a
        TIMEOUT fault. A goal the arm never reaches (a lag model that never settles, a
        model with absurd offsets) must end the berry, not run the stage forever.
        """
        if not math.isfinite(deadline):
            raise ParameterError(f"deadline = {deadline!r}: every ramp must end in finite time")
        step = self.cfg.home_speed * self.cfg.period
        while np.any(q != goal):
            if self.clock.now() > deadline:
                raise Fault(FaultReason.TIMEOUT, f"{stage.value}: ramp not done in time")
            wanted = q + straight_step(q, goal, step)
            # Go on from what was sent: a rate limit or a clamp holds the ramp back.
            q = self._send(wanted)
            seen = self._look(watch, q, need_fix=False) if observe else watch.blind()
            watch.log_step(stage, seen, q, None, None, False)
            self.clock.sleep(self.cfg.period)
        # An open-loop ramp ends where the arm is, not where it was told to be: on a
        # lagging plant the arm trails the ramp, and the next move (the next waypoint,
        # the next berry's placement) would cut the corner through the canes.
        while settle and not self._arrived():
            if self.clock.now() > deadline:
                raise Fault(FaultReason.TIMEOUT, f"{stage.value}: arm not settled in time")
            q = self._send(q)
            seen = self._look(watch, q, need_fix=False) if observe else watch.blind()
            watch.log_step(stage, seen, q, None, None, False)
            self.clock.sleep(self.cfg.period)
        return q

    def _look(self, watch: BerryWatch, q: FloatArray, need_fix: bool) -> Observation:
        """``watch.observe``; a marker lost while the arm is out in the bush at ``q``
        carries ``q`` as the place to back out from (open loop if the cube is gone)."""
        try:
            return watch.observe(need_fix=need_fix)
        except Fault as fault:
            if fault.reason is FaultReason.MARKER_LOST and fault.retreat_from is None:
                fault.retreat_from = q
            raise

    def _arrived(self) -> bool:
        """Whether the lag model (if any) has every actuator within ``arrival_tolerance``
        of the q last sent."""
        left = self.actuator.in_flight()
        return left is None or float(np.max(np.abs(left))) <= self.cfg.arrival_tolerance

    # -- the loop -------------------------------------------------------------------

    def _servo(
        self, watch: BerryWatch, stage: HarvestState, q: FloatArray, axis: FloatArray,
        goal: ServoGoal,
    ) -> StageOutcome:  # fmt: skip
        """Drive the end effector to ``goal.distance`` short of the berry along the
        approach ``axis`` until the error stays below ``goal.tol``; see
        :class:`HarvestConfig` and :class:`ServoGoal` for how else it may end."""
        start = self.clock.now()
        watch.excuse_berry(start)  # the open-loop ramp needed no berry
        progress = Progress(start)
        last: Aim | None = None  # this stage's last measured aim
        while True:
            try:
                seen = self._look(watch, q, need_fix=goal.frozen is None)
            except Fault as fault:
                return self._lost_near(fault, q, axis, last, goal)
            if goal.frozen is not None:
                seen = replace(seen, fix=BerryFix(goal.frozen, "held", seen.t - start))
            if seen.pose is None or seen.fix is None:
                watch.log_step(stage, seen, q, None, None, False)
                q = self._hold(q)
                continue
            aim = last = self._aim(seen, axis, goal.distance)
            if goal.record_errors:  # the errors at the grasp
                watch.record_grasp_errors(self._grasp_error(seen), aim.pointing)
            ended = self._settled_or_out_of_time(watch, stage, seen, q, axis, aim, goal, progress)
            if ended is not None:
                return ended
            q_next, saturated = self._loop_step(q, aim.goal, seen.pose)
            progress.update(seen.t, aim.error, saturated, self.cfg.stall_progress)
            if progress.stalled(seen.t, self.cfg.stall_time):
                return self._stalled(stage, seen, q, axis, aim, goal)
            watch.log_step(stage, seen, q_next, aim.goal, (aim.error, aim.pointing), saturated)
            # Go on from what was sent: the safety layer may have clamped or rate-limited it.
            q = self.actuator.send(q_next)
            self.clock.sleep(self.cfg.period)

    def _aim(self, seen: Observation, axis: FloatArray, distance: float) -> Aim:
        """The grasp point, not the end-effector origin, is servoed onto its goal
        ``distance - grasp_offset`` short of the berry: a residual pointing error then
        does not move the berry off the fingers."""
        assert seen.pose is not None and seen.fix is not None
        offset = self.cfg.grasp_offset
        point = seen.fix.position - (distance - offset) * axis
        goal = tool_pose(seen.pose, point, axis, offset)
        error = float(np.linalg.norm(grasp_point(seen.pose, offset) - point))
        return Aim(goal, error, pointing_error(seen.pose, axis))

    def _grasp_error(self, seen: Observation) -> float:
        """The grasp point's distance (m) from the berry."""
        assert seen.pose is not None and seen.fix is not None
        return float(
            np.linalg.norm(grasp_point(seen.pose, self.cfg.grasp_offset) - seen.fix.position)
        )

    def _loop_step(
        self, q: FloatArray, goal: FloatArray, pose: FloatArray
    ) -> tuple[FloatArray, bool]:
        """The resolver's next command towards ``goal`` from the measured ``pose``."""
        q_next, saturated = self.controller.step(q, goal, pose)
        q_next = np.asarray(q_next, dtype=np.float64)
        if not np.all(np.isfinite(q_next)):
            raise NonFiniteError(f"controller returned q = {q_next.tolist()!r}")
        return q_next, saturated

    def _settled_or_out_of_time(
        self, watch: BerryWatch, stage: HarvestState, seen: Observation, q: FloatArray,
        axis: FloatArray, aim: Aim, goal: ServoGoal, progress: Progress,
    ) -> StageOutcome | None:  # fmt: skip
        """SETTLED after ``settle_steps`` steps within the tolerances; past the budget,
        BUDGET inside ``grasp_within`` (else UNREACHABLE); past the timeout, TIMEOUT;
        else None (the loop goes on)."""
        c = self.cfg
        err, elapsed = aim.error, seen.t - progress.start
        within = err <= goal.tol and aim.pointing <= np.radians(c.angle_tolerance_deg)
        progress.inside = progress.inside + 1 if within else 0
        if progress.inside >= c.settle_steps:
            watch.log_step(stage, seen, q, aim.goal, (err, aim.pointing), False)
            return StageOutcome(q, Ending.SETTLED, axis)
        if goal.budget is not None and elapsed > goal.budget and err <= c.grasp_workspace:
            if err > goal.grasp_within:  # another axis is left to try
                raise Fault(
                    FaultReason.UNREACHABLE,
                    f"{stage.value}: error {err:.4f} m after the {goal.budget:.0f} s budget",
                    retreat_from=q,
                    grasp_error=err,
                )
            self.log.event("fine_budget", t=seen.t, error=err)
            watch.log_step(stage, seen, q, aim.goal, (err, aim.pointing), False)
            return StageOutcome(q, Ending.BUDGET, axis)
        if elapsed > goal.timeout:
            raise Fault(
                FaultReason.TIMEOUT,
                f"{stage.value}: error {err:.4f} m after {elapsed:.1f} s",
                retreat_from=q,
            )
        return None

    def _stalled(
        self, stage: HarvestState, seen: Observation, q: FloatArray, axis: FloatArray,
        aim: Aim, goal: ServoGoal,
    ) -> StageOutcome:  # fmt: skip
        """Saturated on a joint limit without progress: grasp inside ``grasp_within``
        (III-D), hand a placement within ``tol`` over to fine positioning, or
        UNREACHABLE."""
        err, ang = aim.error, aim.pointing
        if goal.budget is not None and err <= goal.grasp_within:
            # On a joint limit but inside the gripper's ±1 cm: grasp (III-D).
            self.log.event("limit_grasp", t=seen.t, error=err)
            return StageOutcome(q, Ending.LIMIT_GRASP, axis)
        if goal.placed_on_limit and err <= goal.tol:
            # Placed, but a joint limit holds the pointing: fine positioning, on the
            # eye-in-hand camera, decides whether the berry can be reached.
            self.log.event("placement_limit", t=seen.t, error=err, pointing=ang)
            return StageOutcome(q, Ending.PLACEMENT_LIMIT, axis)
        raise Fault(
            FaultReason.UNREACHABLE,
            f"{stage.value}: saturated at error {err:.4f} m, pointing {np.degrees(ang):.1f} deg",
            retreat_from=q,
            grasp_error=err if goal.budget is not None else None,
        )

    def _lost_near(
        self, fault: Fault, q: FloatArray, axis: FloatArray, last: Aim | None, goal: ServoGoal
    ) -> StageOutcome:
        """Fine positioning that lost the cube or the berry (MARKER_LOST) with the grasp
        point last measured inside the gripper's ±1 cm (``grasp_workspace``) grasps
        where the arm is, as past the budget on the last axis (III-D): the loop held the
        arm still while the marker was lost, a re-approach would need the marker it
        lost, and the ripeness check at the grasp keeps the last word. Any other fault
        is raised again."""
        if fault.reason is not FaultReason.MARKER_LOST or goal.budget is None or last is None:
            raise fault
        if last.error > self.cfg.grasp_workspace:
            raise fault
        self.log.event("lost_grasp", t=self.clock.now(), error=last.error, detail=str(fault))
        return StageOutcome(q, Ending.LOST_GRASP, axis)

    def _hold(self, q: FloatArray) -> FloatArray:
        """Keep commanding ``q`` (it also feeds the safety layer's watchdog) and wait;
        returns the q sent, the one to go on from."""
        q = self._send(q)
        self.clock.sleep(self.cfg.period)
        return q

    def _send(self, q: FloatArray) -> FloatArray:
        """Command ``q``; returns the q to go on from: what the safety layer let through,
        or ``q`` itself where that differs from it only by the rounding of the m -> psi
        -> m round trip (``SEND_ROUNDING``): holding a q it let through must not drift it."""
        sent = self.actuator.send(q)
        rounding = float(np.max(np.abs(sent - q), initial=0.0)) <= SEND_ROUNDING
        return np.asarray(q, dtype=np.float64) if rounding else sent
