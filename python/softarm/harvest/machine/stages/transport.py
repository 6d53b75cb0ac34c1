"""The arm's moves between the berry loops: a planned segment followed in closed loop on
the eye-to-hand camera (:meth:`Transport.follow`), an open-loop ramp
(:meth:`Transport.ramp`) and the way home through a plan's waypoints; each command's way
checked clear of the canes on the model (:meth:`Transport.clear_way`)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from softarm.errors import NonFiniteError, ParameterError
from softarm.harvest.machine.interfaces import FloatArray, Observation
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.stages.arm_link import ArmLink
from softarm.harvest.machine.states import FaultReason, HarvestState
from softarm.harvest.machine.targets import pointing_error

__all__ = ["WAY_SLACK", "Transport", "straight_step"]


#: How much nearer (m) to a cane than the arm is the way to a command may come, where the
#: arm is already inside ``transport_margin`` (:meth:`Servo._clear_way`): about what one
#: period's step of the loop changes the gap by, so the loop is slowed there, not locked.
WAY_SLACK = 0.001


def straight_step(q: FloatArray, goal: FloatArray, step: float) -> FloatArray:
    """The move (m) from ``q`` towards ``goal`` this period: along the straight line in
    actuator space, the fastest channel at ``step``. The planner checks the canes along
    that line; clipped channel by channel, the channels with the least to go would
    arrive first and the arm would leave the line it was checked along."""
    d = np.asarray(goal, dtype=np.float64) - q
    most = float(np.max(np.abs(d), initial=0.0))
    return d if most <= step else d * (step / most)


class Transport:
    """The moves of the harvest that are not the loop on the berry, on the shared
    :class:`~softarm.harvest.machine.stages.arm_link.ArmLink`."""

    def __init__(self, link: ArmLink) -> None:
        self.link = link

    def follow(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        q_way: FloatArray,
        deadline: float,
        near_ends: bool = False,
        hand_over: bool = True,
    ) -> FloatArray:
        """Follow the planned segment ``q`` → ``q_way`` in closed loop on the eye-to-hand
        camera until the end effector is within ``placement_tolerance`` of the model's pose
        at ``q_way``: once the plan's feedforward has reached ``q_way`` or, with
        ``near_ends`` (a waypoint of the way home), as soon as the arm is there. Without
        ``hand_over`` (the way home's last leg) it ends once the plan's feedforward has
        reached ``q_way``: the ramp home that follows takes the arm the rest of the way
        along the same line, and waiting here for the lag model to have the arm at the
        plan's end, then again at home, waited twice for the regulators.

        Each period the plan's elongations advance by ``home_speed`` (the feedforward of the
        planned q) and the resolver's step, closed on the measured pose towards the model's
        pose at the plan's point where the arm is (:meth:`_plan_at_arm`: the plan's current
        point less the lag), adds the correction: the model's error is taken
        out as the arm goes and the known canes repel it inside the step (planning paper
        eq. 9), where an open-loop ramp would carry the true arm, a few cm off the model,
        into a cane. The resolver alone is local: closed on a waypoint 20-30 cm away it
        saturates on the joint limits, which is why the plan's q leads."""
        c = self.link.cfg
        model_pose = self.link.controller.model_pose
        step = c.home_speed * c.period
        nominal = np.asarray(q, dtype=np.float64).copy()  # the plan's point now
        goal_final = model_pose(q_way)
        best, best_t = np.inf, self.link.clock.now()
        held = False
        posed = best_t  # when the cube's pose was last seen
        while True:
            seen = self.link.look(watch, q, need_fix=False)
            on_plan_end = bool(np.all(nominal == q_way))
            if on_plan_end and not hand_over:
                return q
            if seen.pose is None:
                blind = on_plan_end or seen.t - posed > c.follow_blind_time
                q, nominal = self._blind(watch, stage, seen, q, nominal, q_way, blind)
                continue
            posed = seen.t
            err = float(np.linalg.norm(seen.pose[:3, 3] - goal_final[:3, 3]))
            if self._arrived(seen.t, q, err, on_plan_end, near_ends):
                return q
            if err < best - c.stall_progress:
                best, best_t = err, seen.t
            elif on_plan_end and seen.t - best_t > c.stall_time:
                # The true arm cannot reach the model's pose of this waypoint (a limit, a
                # cane's repulsion): it is only a waypoint, the loop on the berry follows.
                self.link.log.event("waypoint_stalled", t=seen.t, error=err)
                return q
            if seen.t > deadline:
                raise Fault(
                    FaultReason.TIMEOUT,
                    f"{stage.value}: waypoint not reached, error {err:.4f} m",
                    retreat_from=q,
                )
            goal = model_pose(self._plan_at_arm(nominal))
            q_fb, saturated = self.link.controller.follow_step(q, goal, seen.pose)
            advance = straight_step(nominal, q_way, step)
            q_next = self._led(q, q_fb, advance)
            if q_next is q:  # held: the plan waits for the arm
                if not held:
                    self.link.log.event("transport_held", t=seen.t, error=err)
                held = True
            else:
                held = False
                nominal = nominal + advance
            watch.log_step(
                stage, seen, q_next, goal, (err, pointing_error(seen.pose, goal[:3, 2])), saturated
            )
            q = self.link.hold(q_next)  # goes on from what was sent

    def _arrived(
        self, t: float, q: FloatArray, err: float, on_plan_end: bool, near_ends: bool
    ) -> bool:
        """Whether :meth:`follow` ends at ``t`` with the cube ``err`` (m) from the model's
        pose at the segment's end: within ``placement_tolerance`` (at the plan's end, or
        anywhere with ``near_ends``), a waypoint of the way home passed, or handed over."""
        if (on_plan_end or near_ends) and err <= self.link.cfg.placement_tolerance:
            return True
        if near_ends and on_plan_end and self._passing(q):
            self.link.log.event("waypoint_passed", t=t, error=err)
            return True
        if on_plan_end and self._handover():
            # The plan is done and the arm has caught up with it (lag model): what is
            # left is the model's error, which the lag-bounded correction here takes
            # out at a few per cent a period on a slow plant. The loop on the berry
            # that follows takes it out at the predictor's full gain.
            self.link.log.event("waypoint_handover", t=t, error=err)
            return True
        return False

    def _blind(
        self, watch: BerryWatch, stage: HarvestState, seen: Observation, q: FloatArray,
        nominal: FloatArray, q_way: FloatArray, wait: bool,
    ) -> tuple[FloatArray, FloatArray]:  # fmt: skip
        """A period without the cube's pose (a frame dropped, or a fast move's pose
        refused as a jump): the plan's feedforward goes on, open loop and its way
        checked, unless the arm must ``wait`` (past ``follow_blind_time``, or the plan
        done). The q sent and the plan's point."""
        lower, upper = self.link.controller.limits()
        c = self.link.cfg
        advance = straight_step(nominal, q_way, c.home_speed * c.period)
        if wait:
            advance = np.zeros_like(advance)
        q_next = self.clear_way(q, (np.clip(q + advance, lower, upper),))
        if q_next is not q:
            nominal = nominal + advance
        watch.log_step(stage, seen, q_next, None, None, False)
        return self.link.hold(q_next), nominal

    def _plan_at_arm(self, nominal: FloatArray) -> FloatArray:
        """The plan's point where the arm is now, the one the loop's correction compares
        the measured pose with: the plan's point ``nominal`` less the motion still in
        flight to the last command (the lag model's; ``nominal`` itself without one).

        The arm trails the command by the regulators' lag: at ``home_speed`` the gripper
        is a few cm behind the plan's point on the nominal plant (0.08 s), most of a move
        on the slow one (0.8 s). Measured against the
        plan's point, that lag read as an error, and the correction piled up along the
        motion; the arm carried it past the plan's end and came back (tuning seeds
        1280-1282, slow plant: 0.3-1 s a berry, more in the way home). Against the
        plan's point where the arm is, the error is the model's alone, which is what the
        correction is for. The canes' check of each command is as before."""
        flight = self.link.actuator.in_flight()
        return nominal if flight is None else np.asarray(nominal - flight, dtype=np.float64)

    def _led(self, q: FloatArray, q_fb: FloatArray, advance: FloatArray) -> FloatArray:
        """The command of a period with the pose: the plan's motion (feedforward) on top
        of the closed-loop correction ``q_fb``, inside the limits the resolver's own
        command respects, its way clear of the canes; else the plan's motion alone, else
        ``q`` held."""
        lower, upper = self.link.controller.limits()
        q_next = np.clip(np.asarray(q_fb, dtype=np.float64) + advance, lower, upper)
        if not np.all(np.isfinite(q_next)):
            raise NonFiniteError(f"controller returned q = {q_next.tolist()!r}")
        return self.clear_way(q, (q_next, np.clip(q + advance, lower, upper)))

    def _passing(self, q: FloatArray) -> bool:
        """Whether the lag model has the arm within ``placement_tolerance`` of the pose
        the command ``q`` puts it at, on the model: a waypoint of the way home is passed
        there. Measured against the model's pose of the waypoint, a model a few cm off
        the true arm (a slow plant's 1-4 cm) never comes within the tolerance, and the
        leg waited for the arm to come to rest at the waypoint (the hand-over) before
        the next leg began, whose way is checked from where the arm is (False without
        a lag model)."""
        flight = self.link.actuator.in_flight()
        if flight is None:
            return False
        model_pose = self.link.controller.model_pose
        left = model_pose(q)[:3, 3] - model_pose(q - flight)[:3, 3]
        return float(np.linalg.norm(left)) <= self.link.cfg.placement_tolerance

    def _handover(self) -> bool:
        """Whether the lag model has every actuator within ``handover_tolerance`` of the
        last command (False without a lag model: the plan's end is then its pose)."""
        left = self.link.actuator.in_flight()
        return left is not None and float(np.max(np.abs(left))) <= self.link.cfg.handover_tolerance

    def clear_way(self, q: FloatArray, candidates: Sequence[FloatArray]) -> FloatArray:
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
        flight = self.link.actuator.in_flight()
        arm_q = q if flight is None else q - flight
        for candidate in candidates:
            if self._clear(arm_q, candidate):
                return candidate
        return q

    def way_clear(self, q: FloatArray, goal: FloatArray) -> bool:
        """Whether the whole straight way in actuator space from where the lag model has
        the arm (``q`` less the motion in flight) to ``goal`` keeps clear of the canes by
        :meth:`clear_way`'s rule, checked at every period's step of it: a leg that is
        not would hold :meth:`follow` at its first step (each step comes nearer to a cane
        than the arm is) until the way home's timeout, and the open-loop ramp after it
        checks no cane (tag-world seed 1432: 10 s held, then a contact)."""
        flight = self.link.actuator.in_flight()
        arm_q = q if flight is None else q - flight
        c = self.link.cfg
        most = float(np.max(np.abs(np.asarray(goal) - arm_q), initial=0.0))
        steps = max(8, math.ceil(most / (c.home_speed * c.period)) + 1)
        return self._clear(arm_q, goal, steps)

    def _clear(self, arm_q: FloatArray, candidate: FloatArray, steps: int | None = None) -> bool:
        """:meth:`clear_way`'s rule for one straight way from ``arm_q`` to ``candidate``,
        checked at ``steps`` points (the controller's own count by default; True without
        known canes)."""
        way_gaps = self.link.controller.way_gaps
        gaps = way_gaps(arm_q, candidate) if steps is None else way_gaps(arm_q, candidate, steps)
        if gaps is None:
            return True
        need = min(self.link.cfg.transport_margin, float(gaps[0]) - WAY_SLACK)
        return float(np.min(gaps)) >= need

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
        step = self.link.cfg.home_speed * self.link.cfg.period
        while np.any(q != goal):
            if self.link.clock.now() > deadline:
                raise Fault(FaultReason.TIMEOUT, f"{stage.value}: ramp not done in time")
            wanted = q + straight_step(q, goal, step)
            # Go on from what was sent: a rate limit or a clamp holds the ramp back.
            q = self.link.send(wanted)
            seen = self.link.look(watch, q, need_fix=False) if observe else watch.blind()
            watch.log_step(stage, seen, q, None, None, False)
            self.link.clock.sleep(self.link.cfg.period)
        # An open-loop ramp ends where the arm is, not where it was told to be: on a
        # lagging plant the arm trails the ramp, and the next move (the next waypoint,
        # the next berry's placement) would cut the corner through the canes.
        while settle and not self.link.arrived():
            if self.link.clock.now() > deadline:
                raise Fault(FaultReason.TIMEOUT, f"{stage.value}: arm not settled in time")
            q = self.link.send(q)
            seen = self.link.look(watch, q, need_fix=False) if observe else watch.blind()
            watch.log_step(stage, seen, q, None, None, False)
            self.link.clock.sleep(self.link.cfg.period)
        return q

    def way_back(
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
        c = self.link.cfg
        legs = list(way)
        try:
            while legs:
                # The way home's waypoints are places to pass: a leg ends once the arm is
                # at its end (the back-out leaves the arm at the plan's pre-grasp pose, a
                # few mm of elongation off the plan's q after the loop's corrections), and
                # the next leg's way from there is checked as every command's is. The
                # last leg runs to home's q: the open-loop ramp after it is short.
                deadline = start + c.home_timeout
                last = len(legs) == 1
                q = self.follow(watch, stage, q, legs[0], deadline, not last, hand_over=not last)
                legs.pop(0)
        except Fault as fault:
            if fault.reason not in (FaultReason.TIMEOUT, FaultReason.MARKER_LOST):
                raise
            self.link.log.event("return_open_loop", t=self.link.clock.now(), detail=str(fault))
            q = fault.retreat_from if fault.retreat_from is not None else q
            for q_way in legs[:-1]:
                q = self.ramp(watch, stage, q, q_way, self.link.clock.now() + c.home_timeout)
        home = way[-1]
        return self.ramp(watch, stage, q, home, self.link.clock.now() + c.home_timeout)
