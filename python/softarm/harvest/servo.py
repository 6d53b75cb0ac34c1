"""The closed loops inside the harvesting states: wait for the markers, place, fine
position, go home. Each step reads the cameras, checks them, logs, and commands the arm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.errors import NonFiniteError
from softarm.harvest.config import HarvestConfig
from softarm.harvest.interfaces import (
    BerryFix,
    BerryLocator,
    BerryTarget,
    Clock,
    Controller,
    EndEffectorTracker,
    FloatArray,
    PlacementPlanner,
    PressureActuator,
)
from softarm.harvest.log import HarvestLog
from softarm.harvest.report import BerryResult
from softarm.harvest.states import FaultReason, HarvestState
from softarm.harvest.targets import grasp_point, pointing_error, tool_pose

__all__ = ["Fault", "Servo"]


class Fault(Exception):
    """Raised inside a stage to enter the safe state for ``reason``."""

    def __init__(self, reason: FaultReason, detail: str) -> None:
        super().__init__(detail)
        self.reason = reason


@dataclass
class _Seen:
    """What one step observed."""

    t: float
    pose: FloatArray | None
    fix: BerryFix | None


class Servo:
    """Runs the stages of :class:`~softarm.harvest.machine.HarvestMachine`."""

    def __init__(
        self,
        clock: Clock,
        tracker: EndEffectorTracker,
        locator: BerryLocator,
        controller: Controller,
        actuator: PressureActuator,
        config: HarvestConfig,
        log: HarvestLog,
    ) -> None:
        self.clock, self.tracker, self.locator = clock, tracker, locator
        self.controller, self.actuator, self.cfg, self.log = controller, actuator, config, log
        self.state = HarvestState.IDLE
        self._berry = BerryTarget(-1)
        self._result = BerryResult(-1)
        self._pose_seen = self._fix_seen = -np.inf
        self._last_fix: BerryFix | None = None
        #: The approach axis of the current berry (the planner may tilt it).
        self.axis = config.approach_axis
        self._waypoints = []

    def begin(self, berry: BerryTarget, result: BerryResult) -> None:
        """Start a new berry: forget what was seen."""
        self._berry, self._result = berry, result
        self._pose_seen = self._fix_seen = self.clock.now()
        self._last_fix = None
        self.axis = self.cfg.approach_axis
        self._waypoints: list[FloatArray] = []

    # -- stages ---------------------------------------------------------------------

    def wait_visible(self, q: FloatArray) -> None:
        """IDLE: hold the arm until both the cube and the berry are seen."""
        self._pose_seen = self._fix_seen = self.clock.now()
        while True:
            seen = self._observe()
            self._log_step(seen, q, None, None, False)
            if seen.pose is not None and seen.fix is not None:
                return
            self._hold(q)

    def place(self, q: FloatArray, planner: PlacementPlanner | None) -> FloatArray:
        """INITIAL_PLACEMENT: to the pre-grasp pose, ``standoff`` short of the grasp pose.

        With a ``planner`` the pose (and the approach axis, inside the allowed cone) is
        first solved on the model; the plan's waypoints are then followed in closed loop
        (:meth:`follow`, the canes repelling inside the resolver) and the loop closes on
        the berry (eq. 22) to remove the model's error.
        """
        c = self.cfg
        start = self.clock.now()
        if planner is not None:
            seen = self._observe()
            while seen.pose is None or seen.fix is None:
                self._hold(q)
                seen = self._observe()
            plan = planner.plan(q, seen.fix.position, seen.pose)
            if plan is None:
                raise Fault(FaultReason.UNREACHABLE, "no pre-grasp pose in the approach cone")
            waypoints, self.axis = plan
            self._waypoints = list(waypoints)
            self.log.event("plan", t=seen.t, q=waypoints, axis=self.axis, berry=seen.fix.position)
            for q_way in waypoints:
                q = self.follow(q, q_way, start + c.placement_timeout)
        return self._servo(
            q, c.grasp_offset + c.standoff, c.placement_tolerance, c.placement_timeout, None
        )

    def fine(self, q: FloatArray) -> FloatArray:
        """FINE_POSITIONING: grasp point onto the berry (eye-in-hand, eq. 21)."""
        c = self.cfg
        return self._servo(q, c.grasp_offset, c.fine_tolerance, c.fine_timeout, c.fine_budget)

    def go_home(self, q: FloatArray, home: FloatArray) -> FloatArray:
        """RETURN_HOME: back out to the pre-grasp pose (the approach line is free of
        branches), ramp back through the placement plan's waypoints, then to ``home``."""
        c = self.cfg
        start = self.clock.now()
        berry = self._last_fix.position if self._last_fix is not None else None
        try:
            q = self._servo(
                q,
                c.grasp_offset + c.standoff,
                c.placement_tolerance,
                c.home_timeout / 2,
                None,
                frozen=berry,
            )
        except Fault as fault:
            # Backing out is best effort: the berry is already in the fingers, and the
            # ramp home is open loop anyway.
            if fault.reason not in (FaultReason.TIMEOUT, FaultReason.UNREACHABLE):
                raise
            self.log.event("retreat_incomplete", t=self.clock.now(), detail=str(fault))
        # Leave by the planned way in (checked against the known canes), reversed.
        for q_way in reversed(self._waypoints):
            q = self.ramp(q, q_way, start + c.home_timeout)
        return self.ramp(q, home, start + c.home_timeout)

    def follow(self, q: FloatArray, q_way: FloatArray, deadline: float) -> FloatArray:
        """Follow the planned segment ``q`` → ``q_way`` in closed loop on the eye-to-hand
        camera until the end effector is within ``placement_tolerance`` of the model's pose
        at ``q_way``.

        Each period the plan's elongations advance by ``home_speed`` (the feedforward of the
        planned q) and the resolver's step, closed on the measured pose towards the model's
        pose at the plan's current point, adds the correction: the model's error is taken
        out as the arm goes and the known canes repel it inside the step (planning paper
        eq. 9), where an open-loop ramp would carry the true arm, a few cm off the model,
        into a cane. The resolver alone is local: closed on a waypoint 20-30 cm away it
        saturates on the joint limits, which is why the plan's q leads. A controller
        without a model (``model_pose``) falls back to :meth:`ramp`."""
        model_pose = getattr(self.controller, "model_pose", None)
        arm = getattr(self.controller, "arm", None)
        if model_pose is None or arm is None:
            return self.ramp(q, q_way, deadline, observe=True)
        c = self.cfg
        lower, upper = np.asarray(arm.lower), np.asarray(arm.upper)
        step = c.home_speed * c.period
        nominal = np.asarray(q, dtype=np.float64).copy()  # the plan's point now
        goal_final = model_pose(q_way)
        best, best_t = np.inf, self.clock.now()
        while True:
            seen = self._observe(need_fix=False)
            if seen.pose is None:
                self._log_step(seen, q, None, None, False)
                self._hold(q)
                continue
            on_plan_end = bool(np.all(nominal == q_way))
            err = float(np.linalg.norm(seen.pose[:3, 3] - goal_final[:3, 3]))
            if on_plan_end and err <= c.placement_tolerance:
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
                    f"{self.state.value}: waypoint not reached, error {err:.4f} m",
                )
            goal = model_pose(nominal)
            q_fb, saturated = self.controller.step(q, goal, seen.pose)
            advance = np.clip(q_way - nominal, -step, step)
            nominal = nominal + advance
            # Feedforward of the plan's motion on top of the closed-loop correction, kept
            # inside the limits the resolver's own command respects.
            q_next = np.clip(np.asarray(q_fb, dtype=np.float64) + advance, lower, upper)
            if not np.all(np.isfinite(q_next)):
                raise NonFiniteError(f"controller returned q = {q_next.tolist()!r}")
            self._log_step(
                seen, q_next, goal, (err, pointing_error(seen.pose, goal[:3, 2])), saturated
            )
            # Go on from what was sent: the safety layer may have clamped or rate-limited it.
            q = self.actuator.send(q_next)
            self.clock.sleep(c.period)

    def ramp(
        self, q: FloatArray, goal: FloatArray, deadline: float = np.inf, observe: bool = False
    ) -> FloatArray:
        """Move the elongations straight to ``goal`` at ``home_speed``, open loop; with
        ``observe`` the cameras are still read (and checked) at every step."""
        step = self.cfg.home_speed * self.cfg.period
        while np.any(q != goal):
            if self.clock.now() > deadline:
                raise Fault(FaultReason.TIMEOUT, f"{self.state.value}: ramp not done in time")
            q = q + np.clip(goal - q, -step, step)
            self.actuator.send(q)
            seen = self._observe(need_fix=False) if observe else _Seen(self.clock.now(), None, None)
            self._log_step(seen, q, None, None, False)
            self.clock.sleep(self.cfg.period)
        return q

    # -- the loop -------------------------------------------------------------------

    def _servo(
        self,
        q: FloatArray,
        distance: float,
        tol: float,
        timeout: float,
        budget: float | None,
        frozen: FloatArray | None = None,
    ) -> FloatArray:
        """Drive the end effector to ``distance`` short of the berry along the approach
        axis until the error stays below ``tol``; see :class:`HarvestConfig`. With
        ``frozen`` the berry position is that fixed point, not the cameras' (the berry is
        in the fingers on the way back)."""
        c, axis = self.cfg, self.axis
        start = self.clock.now()
        self._fix_seen = max(self._fix_seen, start)  # the open-loop ramp needed no berry
        inside = 0
        best, best_t, saturated_since = np.inf, start, None
        angle_tol = np.radians(c.angle_tolerance_deg)
        while True:
            seen = self._observe(need_fix=frozen is None)
            if frozen is not None:
                seen.fix = BerryFix(frozen, "held", seen.t - start)
            elapsed = seen.t - start
            if seen.pose is None or seen.fix is None:
                self._log_step(seen, q, None, None, False)
                self._hold(q)
                continue
            # The grasp point, not the end-effector origin, is servoed onto its goal
            # ``distance - grasp_offset`` short of the berry: a residual pointing error then
            # does not move the berry off the fingers.
            point = seen.fix.position - (distance - c.grasp_offset) * axis
            goal = tool_pose(seen.pose, point, axis, c.grasp_offset)
            err = float(np.linalg.norm(grasp_point(seen.pose, c.grasp_offset) - point))
            ang = pointing_error(seen.pose, axis)
            if self.state is not HarvestState.RETURN_HOME:  # the errors at the grasp
                self._result.position_error_mm = 1e3 * float(
                    np.linalg.norm(grasp_point(seen.pose, c.grasp_offset) - seen.fix.position)
                )
                self._result.orientation_error_deg = float(np.degrees(ang))
            inside = inside + 1 if err <= tol and ang <= angle_tol else 0
            if inside >= c.settle_steps:
                self._log_step(seen, q, goal, (err, ang), False)
                return q
            if budget is not None and elapsed > budget and err <= c.grasp_workspace:
                self.log.event("fine_budget", t=seen.t, error=err)
                self._log_step(seen, q, goal, (err, ang), False)
                return q
            if elapsed > timeout:
                raise Fault(
                    FaultReason.TIMEOUT,
                    f"{self.state.value}: error {err:.4f} m after {elapsed:.1f} s",
                )
            q_next, saturated = self.controller.step(q, goal, seen.pose)
            q_next = np.asarray(q_next, dtype=np.float64)
            if not np.all(np.isfinite(q_next)):
                raise NonFiniteError(f"controller returned q = {q_next.tolist()!r}")
            if err < best - c.stall_progress:
                best, best_t = err, seen.t
            saturated_since = (saturated_since or seen.t) if saturated else None
            if (
                saturated_since is not None
                and min(seen.t - saturated_since, seen.t - best_t) > c.stall_time
            ):
                if budget is not None and err <= c.grasp_workspace:
                    # On a joint limit but inside the gripper's ±1 cm: grasp (III-D).
                    self.log.event("limit_grasp", t=seen.t, error=err)
                    return q
                if self.state is HarvestState.INITIAL_PLACEMENT and err <= tol:
                    # Placed, but a joint limit holds the pointing: fine positioning, on
                    # the eye-in-hand camera, decides whether the berry can be reached.
                    self.log.event("placement_limit", t=seen.t, error=err, pointing=ang)
                    return q
                raise Fault(
                    FaultReason.UNREACHABLE,
                    f"{self.state.value}: saturated at error {err:.4f} m, "
                    f"pointing {np.degrees(ang):.1f} deg",
                )
            self._log_step(seen, q_next, goal, (err, ang), saturated)
            # Go on from what was sent: the safety layer may have clamped or rate-limited it.
            q = self.actuator.send(q_next)
            self.clock.sleep(c.period)

    def _observe(self, need_fix: bool = True) -> _Seen:
        """Read the tracker and the locator; check for NaN and for markers lost too long
        (the berry only if ``need_fix``)."""
        t = self.clock.now()
        pose = self.tracker.track(t)
        if pose is not None:
            pose = np.asarray(pose, dtype=np.float64)
            if not np.all(np.isfinite(pose)):
                raise NonFiniteError("end-effector pose from the eye-to-hand camera is not finite")
            self._pose_seen = t
        elif t - self._pose_seen > self.cfg.marker_timeout:
            raise Fault(FaultReason.MARKER_LOST, f"cube not seen for {t - self._pose_seen:.2f} s")
        fix = self.locator.locate(t, pose)
        if fix is not None:
            if not np.all(np.isfinite(fix.position)):
                raise NonFiniteError(f"berry position from {fix.camera} is not finite")
            self._fix_seen = t
            self._last_fix = fix
            self._result.target = [float(v) for v in fix.position]
            self._result.cameras[fix.camera] = self._result.cameras.get(fix.camera, 0) + 1
        elif need_fix and t - self._fix_seen > self.cfg.marker_timeout:
            raise Fault(FaultReason.MARKER_LOST, f"berry not seen for {t - self._fix_seen:.2f} s")
        return _Seen(t, pose, fix)

    def _hold(self, q: FloatArray) -> None:
        """Keep commanding ``q`` (it also feeds the safety layer's watchdog) and wait."""
        self.actuator.send(q)
        self.clock.sleep(self.cfg.period)

    def _log_step(
        self,
        seen: _Seen,
        q: FloatArray,
        goal: FloatArray | None,
        errors: tuple[float, float] | None,
        saturated: bool,
    ) -> None:
        self._result.steps += 1
        self.log.step(
            t=seen.t,
            state=self.state,
            berry=self._berry.tag_id,
            q=q,
            pose=seen.pose,
            target=None if seen.fix is None else seen.fix.position,
            camera=None if seen.fix is None else seen.fix.camera,
            target_age=None if seen.fix is None else seen.fix.age,
            goal=None if goal is None else goal[:3, 3],
            position_error=None if errors is None else errors[0],
            orientation_error=None if errors is None else errors[1],
            saturated=saturated,
        )
