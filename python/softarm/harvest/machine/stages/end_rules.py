"""How a stage of the loop on the berry ends (:mod:`.berry_loop`): settled within its
tolerances, past its budget or timeout (:func:`settled_or_out_of_time`; fine positioning
settles on the measured error's upper confidence bound, :func:`confidently_within`),
saturated on a joint limit without progress (:func:`stalled`), or the marker lost near
the berry (:func:`lost_near`). Each returns the stage's :class:`StageOutcome`, raises its
:class:`Fault`, or (the first) returns None: the loop goes on."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.special import stdtrit

from softarm.harvest.machine.interfaces import FloatArray, Observation
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Ending, Fault, StageOutcome
from softarm.harvest.machine.stages.arm_link import ArmLink
from softarm.harvest.machine.stages.goal import Aim, Progress, ServoGoal
from softarm.harvest.machine.states import FaultReason, HarvestState

__all__ = [
    "FINE_AIM_S",
    "Estimate",
    "aimed",
    "confidently_within",
    "jumpy",
    "lost_near",
    "settled_or_out_of_time",
    "stalled",
]

#: With ``fine_aim`` set, fine positioning servoes on to the measured berry for at most
#: this long (s) before the end rule alone may end it (:func:`aimed`).
FINE_AIM_S = 2.0

#: The grasp error estimated from the last ``samples`` measurements: the norm of their
#: mean offset (m) and its upper confidence bound (m).
Estimate = tuple[int, float, float]


def settled_or_out_of_time(
    link: ArmLink, watch: BerryWatch, stage: HarvestState, seen: Observation, q: FloatArray,
    axis: FloatArray, aim: Aim, goal: ServoGoal, progress: Progress,
) -> StageOutcome | None:  # fmt: skip
    """SETTLED within the tolerances (fine positioning under the "confidence"
    ``fine_end_rule``: the error's upper confidence bound, :func:`confidently_within`;
    else ``settle_steps`` steps in a row); past the budget, BUDGET inside
    ``grasp_within`` (else UNREACHABLE); past the timeout, TIMEOUT; else None (the loop
    goes on)."""
    c = link.cfg
    err, elapsed = aim.error, seen.t - progress.start
    pointed = aim.pointing <= np.radians(c.angle_tolerance_deg)
    progress.inside = progress.inside + 1 if err <= goal.tol and pointed else 0
    if goal.budget is None:  # placement, the back-out
        settled = progress.inside >= c.settle_steps
    else:  # fine positioning: on the berry as measured, then the rule
        new = _keep_offset(link, seen, aim, progress)
        on = aimed(progress.offsets, c.settle_steps, elapsed, c.fine_aim)
        if c.fine_end_rule == "confidence":
            settled = on and new and _confident(link, seen, progress, goal, pointed)
        else:
            settled = on and progress.inside >= c.settle_steps
    if settled:
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


def _keep_offset(link: ArmLink, seen: Observation, aim: Aim, progress: Progress) -> bool:
    """This step's measured offset of the grasp point from its goal kept in
    ``progress``; False when it repeats the last one (the same frames read again)."""
    assert seen.pose is not None  # an aim is measured from a pose
    # The grasp point's offset from its goal is the tool pose's offset from its goal:
    # the goal's origin is the grasp point's goal less the offset along the current z.
    return progress.measured(seen.pose[:3, 3] - aim.goal[:3, 3], link.cfg.fine_window)


def aimed(offsets: list[FloatArray], fewest: int, elapsed: float, aim: float) -> bool:
    """Whether fine positioning, ``elapsed`` s in, may end (``fine_aim``): the mean of
    the last ``fewest`` new measured offsets of the grasp point (``offsets``, oldest
    first) within ``aim`` (m) of the berry, or :data:`FINE_AIM_S` spent trying, or
    ``aim`` 0 (off: the end rule alone, the default).

    The end rules accept any measured error within ``fine_tolerance``, and the arm,
    converging from the pre-grasp pose, meets them near the tolerance's edge (0.2 mm
    median at the end in the rendered bush); the measurement's own bias adds to that.
    Servoed on to the measured berry, the true error is the bias alone (docs/harvest.md,
    'What is left with the frustum'). Vectors are averaged, not norms (a norm of noise
    is never 0)."""
    if aim == 0.0 or elapsed >= FINE_AIM_S:
        return True
    if len(offsets) < fewest:
        return False
    return float(np.linalg.norm(np.mean(offsets[-fewest:], axis=0))) <= aim


def _confident(
    link: ArmLink, seen: Observation, progress: Progress, goal: ServoGoal, pointed: bool
) -> bool:
    """Whether the arm is ``pointed`` and the estimate from the offsets kept in
    ``progress`` is within ``goal.tol`` (:func:`confidently_within`; logged when both
    are)."""
    c = link.cfg
    found = confidently_within(progress.offsets, goal.tol, c.settle_steps, c.fine_confidence)
    if found is None or not pointed:
        return False
    link.log.event("fine_confident", t=seen.t, samples=found[0], error=found[1], bound=found[2])
    return True


def confidently_within(
    offsets: list[FloatArray], tol: float, fewest: int, confidence: float
) -> Estimate | None:
    """The grasp error now, estimated from the last n of ``offsets`` (each a measured
    offset of the grasp point from its goal, oldest first), whose upper ``confidence``
    bound is within ``tol``; n from ``fewest`` (at least 2) up to all of them, the
    shortest first; None when no estimate is.

    Two models of the last n offsets, each fitted by least squares per axis: the arm
    still (their mean), and the arm still converging (a straight line in the step,
    evaluated at the last one). An estimate's bound is the norm of its value plus
    Student's t quantile (two-sided, its residuals' degrees of freedom) times its
    standard error, sqrt(trace(residual covariance) x its variance factor). Averaging
    vectors, not norms, keeps noise from biasing the error up (a norm of noise is never
    0): a noisy measurement of an arm on the berry ends once enough of it is in, a
    biased one keeps the estimate off the goal and does not end. The line lets an arm
    converging under little noise (older offsets larger) end as soon as its last
    offsets are on the berry; the mean gains it from more offsets while the arm sits
    still under noise.
    """
    for n in range(max(2, fewest), len(offsets) + 1):
        recent = np.asarray(offsets[-n:], dtype=np.float64)
        steps = np.arange(1 - n, 1, dtype=np.float64)  # 0 at the last offset
        for columns in (1, 2) if n > 2 else (1,):
            design = np.column_stack([np.ones(n), steps][:columns])
            bound = _bound(design, recent, confidence)
            if bound[1] <= tol:
                return n, bound[0], bound[1]
    return None


def _bound(design: FloatArray, offsets: FloatArray, confidence: float) -> tuple[float, float]:
    """The least-squares fit of ``offsets`` (n, 3) on ``design`` (n, p; the first column
    ones, the last row the step to estimate at): the norm of its value at the last step
    and that norm's upper ``confidence`` bound."""
    coef, *_ = np.linalg.lstsq(design, offsets, rcond=None)
    n, p = design.shape
    residual = offsets - design @ coef
    spread = float(np.sum(residual**2)) / (n - p)  # trace of the residual covariance
    at = design[-1]
    factor = float(at @ np.linalg.solve(design.T @ design, at))  # 1/n for the mean
    value = float(np.linalg.norm(at @ coef))
    return value, value + _t_quantile(confidence, n - p) * float(np.sqrt(spread * factor))


@lru_cache(maxsize=256)
def _t_quantile(confidence: float, dof: int) -> float:
    """Student's t two-sided ``confidence`` quantile at ``dof`` degrees of freedom."""
    # scipy.special's, not scipy.stats's: that import costs every run 0.6 s.
    return float(stdtrit(dof, 0.5 + 0.5 * confidence))


def jumpy(
    link: ArmLink, stage: HarvestState, seen: Observation, q: FloatArray, aim: Aim,
    jumps: int, goal: ServoGoal,
) -> None:  # fmt: skip
    """After ``goal.give_up`` jumps of the measurement (:class:`~softarm.harvest.
    machine.stages.jumps.JumpCounter`; fine positioning with another axis left),
    UNREACHABLE: the arm backs out and approaches along another axis of the cone, from
    which C1 sees the cube from another side. A jumping measurement does not say where
    the arm is: the attempt counts as ending at the edge of the gripper's reach
    (``grasp_workspace``), to come back to only as the nearest attempt would be (no
    other axis planned, or the last one stalled farther out), and then to grasp within
    that reach at the budget, as without a re-approach."""
    if goal.give_up is None or jumps < goal.give_up:
        return
    link.log.event("jumpy_axis", t=seen.t, jumps=jumps, error=aim.error)
    raise Fault(
        FaultReason.UNREACHABLE,
        f"{stage.value}: the measurement jumped {jumps} times on this axis",
        retreat_from=q,
        grasp_error=link.cfg.grasp_workspace,
    )


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
