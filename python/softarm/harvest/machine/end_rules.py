"""How a stage of the loop on the berry ends (:mod:`.berry_loop`): settled within its
tolerances, past its budget or timeout (:func:`settled_or_out_of_time`), saturated on a
joint limit without progress (:func:`stalled`), or the marker lost near the berry
(:func:`lost_near`). Each returns the stage's :class:`StageOutcome`, raises its
:class:`Fault`, or (the first) returns None: the loop goes on."""

from __future__ import annotations

import numpy as np

from softarm.harvest.machine.arm_link import ArmLink
from softarm.harvest.machine.interfaces import FloatArray, Observation
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Ending, Fault, StageOutcome
from softarm.harvest.machine.servo_goal import Aim, Progress, ServoGoal
from softarm.harvest.machine.states import FaultReason, HarvestState

__all__ = ["lost_near", "settled_or_out_of_time", "stalled"]


def settled_or_out_of_time(
    link: ArmLink, watch: BerryWatch, stage: HarvestState, seen: Observation, q: FloatArray,
    axis: FloatArray, aim: Aim, goal: ServoGoal, progress: Progress,
) -> StageOutcome | None:  # fmt: skip
    """SETTLED after ``settle_steps`` steps within the tolerances; past the budget,
    BUDGET inside ``grasp_within`` (else UNREACHABLE); past the timeout, TIMEOUT;
    else None (the loop goes on)."""
    c = link.cfg
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
        link.log.event("fine_budget", t=seen.t, error=err)
        watch.log_step(stage, seen, q, aim.goal, (err, aim.pointing), False)
        return StageOutcome(q, Ending.BUDGET, axis)
    if elapsed > goal.timeout:
        raise Fault(
            FaultReason.TIMEOUT,
            f"{stage.value}: error {err:.4f} m after {elapsed:.1f} s",
            retreat_from=q,
        )
    return None


def stalled(
    link: ArmLink, stage: HarvestState, seen: Observation, q: FloatArray, axis: FloatArray,
    aim: Aim, goal: ServoGoal,
) -> StageOutcome:  # fmt: skip
    """Saturated on a joint limit without progress: grasp inside ``grasp_within``
    (III-D), hand a placement within ``tol`` over to fine positioning, or
    UNREACHABLE."""
    err, ang = aim.error, aim.pointing
    if goal.budget is not None and err <= goal.grasp_within:
        # On a joint limit but inside the gripper's ±1 cm: grasp (III-D).
        link.log.event("limit_grasp", t=seen.t, error=err)
        return StageOutcome(q, Ending.LIMIT_GRASP, axis)
    if goal.placed_on_limit and err <= goal.tol:
        # Placed, but a joint limit holds the pointing: fine positioning, on the
        # eye-in-hand camera, decides whether the berry can be reached.
        link.log.event("placement_limit", t=seen.t, error=err, pointing=ang)
        return StageOutcome(q, Ending.PLACEMENT_LIMIT, axis)
    raise Fault(
        FaultReason.UNREACHABLE,
        f"{stage.value}: saturated at error {err:.4f} m, pointing {np.degrees(ang):.1f} deg",
        retreat_from=q,
        grasp_error=err if goal.budget is not None else None,
    )


def lost_near(
    link: ArmLink, fault: Fault, q: FloatArray, axis: FloatArray, last: Aim | None, goal: ServoGoal
) -> StageOutcome:
    """Fine positioning that lost the cube or the berry (MARKER_LOST) with the grasp
    point last measured inside the gripper's ±1 cm (``grasp_workspace``) grasps
    where the arm is, as past the budget on the last axis (III-D): the loop held the
    arm still while the marker was lost, a re-approach would need the marker it
    lost, and the ripeness check at the grasp keeps the last word. Any other fault
    is raised again."""
    if fault.reason is not FaultReason.MARKER_LOST or goal.budget is None or last is None:
        raise fault
    if last.error > link.cfg.grasp_workspace:
        raise fault
    link.log.event("lost_grasp", t=link.clock.now(), error=last.error, detail=str(fault))
    return StageOutcome(q, Ending.LOST_GRASP, axis)
