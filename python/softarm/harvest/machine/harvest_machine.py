"""The harvesting state machine (paper section III-D, fig. 4).

Per berry::

    IDLE → INITIAL_PLACEMENT → FINE_POSITIONING → GRASP → RETURN_HOME → DONE
      └──────────────┴────────────────┴────────────┴──────────┴──→ FAULT (vented)

* IDLE: select the berry's tag; ramp the command to the ready pose (placement goes on
  from where the arm is); wait until the cube and the berry are both seen.
* INITIAL_PLACEMENT: eye-to-hand feedback (eq. 22) drives the gripper to a pre-grasp pose
  ``standoff`` short of the berry, facing it along ``approach``.
* FINE_POSITIONING: the berry position from the eye-in-hand camera (eq. 21), held while
  hidden, drives the grasp point onto the berry.
* GRASP: close, read the ripeness; an unripe berry is released and skipped.
* RETURN_HOME: back out along the approach axis, then ramp to the ready pose.

Every transition is logged (and fsync'd) with its reason. A fault vents every channel at
once, logs the reason, and ends the berry in FAULT; :data:`~softarm.harvest.machine.states.
FAULTS_THAT_STOP` also end the run, the others go on with the next berry. A closed loop
that gives up on the berry with the arm sound (saturated on the joint limits short of it,
or out of time) first backs out home the way it came (RETURN_HOME), so that the vent does
not relax the arm through the canes; after a stall it re-approaches along another axis
(``HarvestConfig.reapproaches``) before it faults.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from softarm.errors import HardwareError, NonFiniteError, SafetyError, VisionError
from softarm.harvest.control.survey import SurveyPlan
from softarm.harvest.machine.interfaces import (
    BerryTarget,
    Clock,
    Controller,
    FloatArray,
    Gripper,
    GroundTruth,
    PlacementPlanner,
    PressureActuator,
    RipenessSensor,
    Vision,
)
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.reapproach import Attempt, Reapproach
from softarm.harvest.machine.stages.servo import Servo
from softarm.harvest.machine.states import FaultReason, HarvestState
from softarm.harvest.records.bush_map_record import map_record
from softarm.harvest.records.log import HarvestLog
from softarm.harvest.records.report import BerryResult
from softarm.harvest_config import HarvestConfig
from softarm.perception.bush_map import BushMap

__all__ = ["HarvestMachine"]


#: The survey's steps and transitions are logged under this target (no berry's id).
SURVEY = BerryTarget(-1)
#: A view of C2 (:meth:`softarm.vision.two_cameras.CameraVision.view_c2`): its image
#: and its pose in the base frame.
View = tuple[Any, FloatArray]
ViewSource = Callable[[float], View | None]
#: What ends a berry (or the survey) in FAULT, vented, the harvest going on: a stage's
#: own Fault and the device, measurement and vision errors (:func:`_reason`).
STAGE_ERRORS = (Fault, SafetyError, NonFiniteError, HardwareError, VisionError)


class HarvestMachine:
    """Harvests berries one at a time with the devices given (see module docstring).

    The machine alone owns the harvest state, the current berry's approach axis and
    :class:`~softarm.harvest.records.report.BerryResult`: the stages (:class:`~softarm.harvest.
    servo.Servo`) are told what they need and return a
    :class:`~softarm.harvest.machine.outcome.StageOutcome`; what they observed along the way (also
    up to a fault) is in the berry's :class:`~softarm.harvest.machine.observe.BerryWatch`, which
    the machine records into the result when the berry ends.

    Args:
        clock, vision, controller, actuator, gripper, ripeness: the
            :mod:`softarm.harvest.machine.interfaces` the machine runs on.
        n_actuators: length of q.
        config: tuning; defaults follow the paper.
        log: where steps and transitions go (in memory by default).
        ground_truth: simulation only, to report true errors at the grasp.
        planner: plans placement on the model first (see :mod:`softarm.harvest.control.ik`);
            without one the resolver closes the loop from the ready pose directly.
    """

    def __init__(
        self,
        clock: Clock,
        vision: Vision,
        controller: Controller,
        actuator: PressureActuator,
        gripper: Gripper,
        ripeness: RipenessSensor,
        n_actuators: int = 9,
        config: HarvestConfig | None = None,
        log: HarvestLog | None = None,
        ground_truth: GroundTruth | None = None,
        planner: PlacementPlanner | None = None,
    ) -> None:
        self.clock = clock
        self.vision = vision
        self.actuator = actuator
        self.gripper = gripper
        self.ripeness = ripeness
        self.config = config or HarvestConfig()
        self.log = log or HarvestLog()
        self.ground_truth = ground_truth
        self.state = HarvestState.IDLE
        #: The ready pose between berries: straight, every actuator at ``home_elongation``,
        #: away from the lower limits where the resolver's steps would be clipped.
        self.home: FloatArray = np.full(n_actuators, self.config.home_elongation)
        self.servo = Servo(clock, controller, actuator, self.config, self.log)
        self.planner = planner
        #: The approach axis of the current berry (a placement planner may tilt it).
        self.axis: FloatArray = self.config.approach_axis
        #: The pre-grasp distance (m) of the attempt under way (its plan's).
        self.standoff: float = self.config.standoff

    @property
    def q(self) -> FloatArray:
        """Commanded elongations (m): what the safety layer last let through, the one
        copy of the command (every stage goes on from it; a vent zeroes it). The soft
        arm has no joint sensors, so the resolver's Jacobian is evaluated at the
        command, and the measured pose closes the loop."""
        return self.actuator.sent

    def run_berry(self, berry: BerryTarget, grasp: bool = True) -> BerryResult:
        """Take one berry through the whole workflow; never raises for a device fault.

        With ``grasp=False`` the machine stops after fine positioning (DONE with the
        gripper on the berry): visual servoing only, e.g. to check a calibration.
        """
        result = BerryResult(berry.tag_id)
        start = self.clock.now()
        watch = BerryWatch(self.vision, self.clock, berry, self.log, self.config.marker_timeout)
        self.axis = self.config.approach_axis
        self.standoff = self.config.standoff
        servo = self.servo
        self._transition(HarvestState.IDLE, berry, "new berry")
        try:
            self.vision.select(berry)
            idle_deadline = self.clock.now() + self.config.idle_timeout
            # Not settled: placement follows its plan from where the lag model has the
            # arm, each command's way checked from there (Transport.clear_way), so the
            # first berry need not wait for the arm to rise from vented (0.2 s a berry
            # on the slow plant's tag world; docs/harvest.md).
            servo.transport.ramp(watch, self.state, self.q, self.home, idle_deadline, settle=False)
            servo.wait_visible(watch, self.state, self.q)
            self._transition(HarvestState.INITIAL_PLACEMENT, berry, "cube and berry in view")
            waypoints = self._reach(watch, berry)
            self._record_grasp_errors(berry, result)
            if not grasp:
                self._transition(HarvestState.DONE, berry, "positioned; no grasp requested")
                return self._finish(result, watch, start)
            self._transition(HarvestState.GRASP, berry, "berry within the grasp workspace")
            self._grasp(result)
            self._transition(HarvestState.RETURN_HOME, berry, "grasp finished")
            servo.go_home(
                watch, self.state, self.q, self.home, self.axis, waypoints, watch.last_fix,
                self.standoff,
            )  # fmt: skip
            if result.harvested:
                self.gripper.open()  # drop the berry at the rest pose
            self._transition(
                HarvestState.DONE, berry, "harvested" if result.harvested else "skipped"
            )
        except STAGE_ERRORS as exc:
            self._fault(berry, result, _reason(exc), _detail(exc))
        except BaseException as exc:
            # A bug or Ctrl-C: still leave the arm vented and the log synced, then re-raise.
            _unexpected(self, berry.tag_id, exc)
            raise
        return self._finish(result, watch, start)

    def survey(self, plan: SurveyPlan, view: ViewSource) -> list[tuple[View, View]]:
        """SURVEY: ramp to each pair's two configurations in turn (open loop, as
        placement's ramps; the plan checked them), ``view(t)`` once the arm has settled
        at each, then ramp to the ready pose; the pairs whose two views were both taken.
        A fault ends the survey where it is, vented and logged like a berry's, with the
        pairs taken before it; the harvest goes on from IDLE."""
        watch = BerryWatch(self.vision, self.clock, SURVEY, self.log, self.config.marker_timeout)
        self._transition(HarvestState.SURVEY, SURVEY, f"{len(plan.pairs)} pairs of views planned")
        pairs: list[tuple[View, View]] = []
        try:
            for first, second in plan.pairs:
                views = [self._take_view(watch, q, view) for q in (first, second)]
                if views[0] is not None and views[1] is not None:
                    pairs.append((views[0], views[1]))
            deadline = self.clock.now() + self.config.idle_timeout
            self.servo.transport.ramp(watch, self.state, self.q, self.home, deadline)
            self._transition(HarvestState.IDLE, SURVEY, f"survey done: {len(pairs)} pairs of views")
        except STAGE_ERRORS as exc:
            self._fault(SURVEY, BerryResult(SURVEY.tag_id), _reason(exc), _detail(exc))
        except BaseException as exc:
            _unexpected(self, SURVEY.tag_id, exc)
            raise
        return pairs

    def _take_view(self, watch: BerryWatch, q: FloatArray, view: ViewSource) -> View | None:
        """Ramp to ``q``, settle, and take ``view`` there (None: C1 lost the cube or C2
        gave no frame)."""
        deadline = self.clock.now() + self.config.idle_timeout
        self.servo.transport.ramp(watch, self.state, self.q, q, deadline)
        taken = view(self.clock.now())
        self.log.event("survey_view", t=self.clock.now(), taken=taken is not None)
        return taken

    def _reach(self, watch: BerryWatch, berry: BerryTarget) -> tuple[FloatArray, ...]:
        """INITIAL_PLACEMENT then FINE_POSITIONING (the grasp point onto the berry);
        returns the placement plan's waypoints, the way back out.

        A plan is the model's: the true arm, a few % off it, may need a channel past its
        joint limit to reach the berry along the planned axis, and then the loop saturates
        short of it. Such a stall (in fine positioning, one farther than
        ``stall_progress`` from the berry) backs the arm out home the way it came and
        plans again along another axis of the cone, up to ``reapproaches`` times. The
        last new axis grasps only if it ends no farther from the berry than the nearest
        earlier stall inside the gripper's reach; else the arm comes back to that one's
        plan and grasps where it ends, as it does when a re-approach finds no other axis
        in the cone. A last stall, or a time-out, also backs out
        before the fault: vented in the bush, the arm would relax to its rest shape
        through the canes."""
        c = self.config
        policy = Reapproach(
            c.reapproaches, c.stall_progress, c.grasp_workspace, self.planner is not None
        )
        while True:
            waypoints, self.axis, self.standoff = self._next_plan(watch, policy)
            try:
                self.servo.place(watch, self.state, self.q, self.axis, waypoints, self.standoff)
                self._transition(HarvestState.FINE_POSITIONING, berry, "pre-grasp pose reached")
                self.servo.fine(
                    watch, self.state, self.q, self.axis, policy.grasp_within(), policy.more()
                )
                return waypoints
            except Fault as fault:
                if fault.retreat_from is None:
                    raise
                why = policy.after(fault, self.axis, waypoints, self.standoff)
                leaving = why or "backing out before the fault"
                self._transition(HarvestState.RETURN_HOME, berry, f"{leaving}: {fault}")
                try:
                    self.servo.go_home(
                        watch, self.state, self.q, self.home, self.axis, waypoints,
                        watch.last_fix, self.standoff,
                    )  # fmt: skip
                except Fault as failed:
                    self.log.event("retreat_failed", t=self.clock.now(), detail=str(failed))
                    raise fault from failed
                if why is None:
                    raise
                reason = policy.again(self.axis)
                self.servo.wait_visible(watch, self.state, self.q)
                self._transition(HarvestState.INITIAL_PLACEMENT, berry, reason)

    def _next_plan(
        self, watch: BerryWatch, policy: Reapproach
    ) -> tuple[tuple[FloatArray, ...], FloatArray, float]:
        """The next attempt's waypoints, axis and standoff: the plan of the attempt ``policy``
        comes back to; else a new plan along an axis not tried; when a re-approach finds
        none, the nearest earlier attempt inside the gripper's reach, come back to as
        after a last stall (without it the berry is UNREACHABLE); without a planner, the
        configured axis."""
        if policy.back_to is not None:
            return self._attempt(policy.back_to)
        if self.planner is None:
            return (), self.config.approach_axis, self.config.standoff
        try:
            return self.servo.plan(watch, self.q, self.planner, policy.tried)
        except Fault as fault:
            nearest = policy.nearest
            if not policy.tried or nearest is None or fault.reason is not FaultReason.UNREACHABLE:
                raise
            self.log.event(
                "no_other_axis", t=self.clock.now(), back_to_mm=1e3 * nearest.grasp_error
            )
            policy.back_to = nearest
            return self._attempt(nearest)

    def _attempt(self, attempt: Attempt) -> tuple[tuple[FloatArray, ...], FloatArray, float]:
        """An earlier ``attempt``'s waypoints, axis and standoff, to come back to."""
        standoff = self.config.standoff if attempt.standoff is None else attempt.standoff
        return attempt.waypoints, attempt.axis, standoff

    def _finish(self, result: BerryResult, watch: BerryWatch, start: float) -> BerryResult:
        """Record what the stages observed, the final state and the time into ``result``."""
        if watch.last_fix is not None:
            result.target = [float(v) for v in watch.last_fix]
        if watch.grasp_errors is not None:
            position, pointing = watch.grasp_errors
            result.position_error_mm = 1e3 * position
            result.orientation_error_deg = float(np.degrees(pointing))
        result.steps = watch.steps
        result.cameras = dict(watch.cameras.items())
        result.final_state = self.state
        result.duration_s = self.clock.now() - start
        self.log.event("berry_result", **result.to_dict())
        return result

    def _grasp(self, result: BerryResult) -> None:
        self.gripper.close()
        ripeness = float(self.ripeness.read())
        if not np.isfinite(ripeness):
            raise Fault(FaultReason.NAN_MEASUREMENT, f"ripeness reading {ripeness!r}")
        self.log.event("ripeness", value=ripeness, threshold=self.config.ripeness_threshold)
        if ripeness < self.config.ripeness_threshold:
            self.gripper.open()
            result.skipped_unripe = True
        else:
            result.harvested = True

    def _record_grasp_errors(self, berry: BerryTarget, result: BerryResult) -> None:
        if self.ground_truth is None:
            return
        pos, ang = self.ground_truth.grasp_errors(berry, self.axis)
        result.true_position_error_mm = 1e3 * pos
        result.true_orientation_error_deg = float(np.degrees(ang))

    def _transition(self, new: HarvestState, berry: BerryTarget, reason: str) -> None:
        old, self.state = self.state, new
        self.log.event(
            "transition", t=self.clock.now(), berry=berry.tag_id, old=old, new=new, why=reason
        )

    def _fault(
        self, berry: BerryTarget, result: BerryResult, reason: FaultReason, detail: str
    ) -> None:
        result.fault = reason
        result.harvested = False
        self._vent(f"{reason.value}: {detail}")
        self.log.event(
            "fault", t=self.clock.now(), berry=berry.tag_id, reason=reason, detail=detail
        )
        self._transition(HarvestState.FAULT, berry, f"{reason.value}: {detail}")

    def log_map(self, bush_map: BushMap) -> None:
        """Log the bush map as it is now (a ``bush_map`` record: the berries perception
        found and the canes it fitted), after each C1 look of the markerless loop."""
        self.log.event("bush_map", t=self.clock.now(), **map_record(bush_map))

    def _vent(self, reason: str) -> None:
        """The safe state: every channel exhausted; the arm relaxes to its rest shape."""
        try:
            self.actuator.vent(reason)
            vented = True
        except Exception as exc:  # a dead driver must not hide the original fault
            self.log.event("vent_failed", error=repr(exc))
            vented = False
        self.log.event("vent", t=self.clock.now(), reason=reason, ok=vented)


def _unexpected(machine: HarvestMachine, tag_id: int, exc: BaseException) -> None:
    """Vent after a bug, logged as a ``crash``, or after a stop (Ctrl-C, SIGTERM, an
    exit: not an :class:`Exception`), logged as ``interrupted``, as the command's own
    record of the stop is."""
    if isinstance(exc, Exception):
        machine._vent(f"unexpected {exc!r}")
        machine.log.event("crash", berry=tag_id, error=repr(exc))
        return
    why = str(exc) or type(exc).__name__
    machine._vent(f"stopped: {why}")
    machine.log.event("interrupted", berry=tag_id, reason=why)


def _reason(exc: BaseException) -> FaultReason:
    """The fault reason of an exception of :data:`STAGE_ERRORS`."""
    if isinstance(exc, Fault):
        return exc.reason
    if isinstance(exc, SafetyError):
        return FaultReason.SAFETY_STOP
    if isinstance(exc, NonFiniteError):
        return FaultReason.NAN_MEASUREMENT
    if isinstance(exc, HardwareError):
        return FaultReason.HARDWARE_ERROR
    return FaultReason.VISION_ERROR


def _detail(exc: BaseException) -> str:
    """What the fault log says of ``exc``: a stage's own message, else the error."""
    return str(exc) if isinstance(exc, Fault) else repr(exc)
