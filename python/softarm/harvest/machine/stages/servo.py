"""The stages inside the harvesting states: wait for the markers, plan, place, fine
position, go home. Each is the loop on the berry (:mod:`.berry_loop`) with its goal, or a
move of :mod:`.transport`, on the devices and settings they share (:mod:`.arm_link`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from softarm.harvest.machine.interfaces import (
    Clock,
    Controller,
    FloatArray,
    PlacementPlanner,
    PressureActuator,
    require_controller,
)
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Ending, Fault, StageOutcome
from softarm.harvest.machine.stages.arm_link import ArmLink
from softarm.harvest.machine.stages.berry_loop import BerryLoop
from softarm.harvest.machine.stages.goal import ServoGoal
from softarm.harvest.machine.stages.transport import Transport
from softarm.harvest.machine.states import FaultReason, HarvestState
from softarm.harvest.records.log import HarvestLog
from softarm.harvest_config import HarvestConfig

__all__ = ["BACK_OUT_AHEAD_WITHIN", "FINE_GIVE_UP", "Fault", "Servo"]

#: How near (m) the pre-grasp pose the back-out must measure the arm before it may end on
#: where the commands already sent put it (:class:`ServoGoal` ``ahead_within``): the way
#: home then starts while the arm is still on the approach line's last 2 cm, which the
#: plan checked clear of the canes. Ended ahead from farther out, the way home cut the
#: corner from the approach line to 5.4 mm from a cane (fresh seed 1356).
BACK_OUT_AHEAD_WITHIN = 0.02

#: After how many jumps of the measured grasp error (:mod:`.jumps`) fine positioning gives
#: its approach axis up while another is left to try: on diagnosis seeds 1410-1419 a
#: berry C1 saw well gave 0-2 in its whole fine positioning, one it did not 10 within
#: 0.9-1.7 s, and 12 s of them after.
FINE_GIVE_UP = 10


class Servo:
    """Runs the stages of :class:`~softarm.harvest.machine.harvest_machine.HarvestMachine`.

    It keeps no state of a berry or of the machine: each stage is told the berry's
    :class:`~softarm.harvest.machine.observe.BerryWatch`, the ``stage`` it runs as (for the step
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
        self.link = ArmLink(clock, require_controller(controller), actuator, config, log)
        self.transport = Transport(self.link)
        self.berry_loop = BerryLoop(self.link)

    @property
    def controller(self) -> Controller:
        """The controller every stage steps with (one, in :attr:`link`)."""
        return self.link.controller

    @controller.setter
    def controller(self, controller: Controller) -> None:
        self.link.controller = require_controller(controller)

    # -- stages ---------------------------------------------------------------------

    def wait_visible(self, watch: BerryWatch, stage: HarvestState, q: FloatArray) -> None:
        """IDLE: hold the arm until both the cube and the berry are seen."""
        watch.restart()
        while True:
            seen = watch.observe()
            watch.log_step(stage, seen, q, None, None, False)
            if seen.pose is not None and seen.fix is not None:
                return
            q = self.link.hold(q)

    def plan(
        self,
        watch: BerryWatch,
        q: FloatArray,
        planner: PlacementPlanner,
        avoid: Sequence[FloatArray] = (),
    ) -> tuple[tuple[FloatArray, ...], FloatArray, float]:
        """INITIAL_PLACEMENT, first: solve the pre-grasp pose (and the approach axis,
        inside the allowed cone, none of ``avoid``) on the model, holding ``q`` until the
        cube and the berry are seen. Returns the plan's waypoints, its axis and its
        pre-grasp distance (m; the planner's ``standoff`` where it has one, else
        ``[harvest] standoff``); no plan is UNREACHABLE."""
        seen = watch.observe()
        while seen.pose is None or seen.fix is None:
            q = self.link.hold(q)
            seen = watch.observe()
        plan = planner.plan(q, seen.fix.position, seen.pose, avoid)
        if plan is None:
            raise Fault(FaultReason.UNREACHABLE, "no pre-grasp pose in the approach cone")
        planned, axis = plan
        standoff = float(getattr(planner, "standoff", self.link.cfg.standoff))
        self.link.log.event(
            "plan", t=seen.t, q=planned, axis=axis, berry=seen.fix.position,
            fell_back=bool(getattr(planner, "fell_back", False)), standoff=standoff,
        )  # fmt: skip
        return tuple(planned), axis, standoff

    def place(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        axis: FloatArray,
        waypoints: tuple[FloatArray, ...] = (),
        standoff: float | None = None,
    ) -> StageOutcome:
        """INITIAL_PLACEMENT: to the pre-grasp pose, ``standoff`` (m; the plan's, by
        default ``[harvest] standoff``) short of the grasp pose, approaching along ``axis``.

        A plan's ``waypoints`` (:meth:`plan`) are first followed in closed loop
        (:meth:`Transport.follow`, the canes repelling inside the resolver), then the loop closes
        on the berry (eq. 22) to remove the model's error. The outcome carries the axis
        and the waypoints used."""
        c = self.link.cfg
        start = self.link.clock.now()
        for q_way in waypoints:
            q = self.transport.follow(watch, stage, q, q_way, start + c.placement_timeout)
        pre_grasp = c.standoff if standoff is None else standoff
        placement = ServoGoal(
            c.grasp_offset + pre_grasp, c.placement_tolerance, c.placement_timeout,
            placed_on_limit=True, ahead=True,
        )  # fmt: skip
        out = self.berry_loop.run(watch, stage, q, axis, placement)
        return replace(out, waypoints=waypoints)

    def fine(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        axis: FloatArray,
        grasp_within: float | None = None,
        another_axis: bool = False,
    ) -> StageOutcome:
        """FINE_POSITIONING: grasp point onto the berry (eye-in-hand, eq. 21).

        Saturated on a joint limit without progress, or past ``fine_budget``, it grasps
        inside the gripper's ±1 cm (III-D), or only within ``grasp_within`` (m) when the
        machine has a better use for the arm (another axis to try, an earlier attempt
        that ended nearer): farther out it is UNREACHABLE here, with the error. With
        ``another_axis`` left to try, ``FINE_GIVE_UP`` jumps of the measured error
        (:mod:`.jumps`: C1 does not see the cube well from this axis) give the axis up,
        UNREACHABLE, at once."""
        c = self.link.cfg
        within = c.grasp_workspace if grasp_within is None else grasp_within
        fine = ServoGoal(
            c.grasp_offset, c.fine_tolerance, c.fine_timeout, c.fine_budget, within,
            give_up=FINE_GIVE_UP if another_axis else None,
        )  # fmt: skip
        return self.berry_loop.run(watch, stage, q, axis, fine)

    def go_home(
        self,
        watch: BerryWatch,
        stage: HarvestState,
        q: FloatArray,
        home: FloatArray,
        axis: FloatArray,
        waypoints: tuple[FloatArray, ...],
        berry: FloatArray | None,
        standoff: float | None = None,
    ) -> FloatArray:
        """RETURN_HOME: back out to the pre-grasp pose, ``standoff`` short of the grasp
        pose as placed (the approach line is free of
        branches) of the ``berry`` last seen, along ``axis``, ramp back through the
        placement plan's ``waypoints``, then to ``home``. Within
        ``BACK_OUT_AHEAD_WITHIN`` of the pre-grasp pose the back-out ends on where the
        commands sent put the arm, as placement does."""
        c = self.link.cfg
        start = self.link.clock.now()
        try:
            pre_grasp = c.standoff if standoff is None else standoff
            back_out = ServoGoal(
                c.grasp_offset + pre_grasp, c.placement_tolerance, c.home_timeout / 2,
                record_errors=False, frozen=berry, ahead=True,
                ahead_within=BACK_OUT_AHEAD_WITHIN,
            )  # fmt: skip
            backed = self.berry_loop.run(watch, stage, q, axis, back_out)
            q = backed.q
            after = waypoints[-2] if len(waypoints) > 1 else home
            if backed.ending is Ending.SETTLED and waypoints and self.transport.way_clear(q, after):
                # The back-out has the arm at the pre-grasp pose, the plan's last
                # waypoint, measured on the berry (or within 2 cm of it with the commands
                # sent putting it there): the way home starts at the leg after it. Sent
                # back to the plan's q there first, the arm moved by the model's error
                # (1-4 cm on a slow plant) and waited to arrive. Where the straight way
                # on from the arm's q is not clear of the canes (the plan checked its
                # own q's), the plan's q stays the first leg.
                waypoints = waypoints[:-1]
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
            self.link.log.event("retreat_incomplete", t=self.link.clock.now(), detail=str(fault))
            if fault.retreat_from is not None:  # where the loop left the arm
                q = fault.retreat_from
        return self.transport.way_back(watch, stage, q, (*reversed(waypoints), home), start)
