"""Tuning of the harvesting state machine (SI units).

Below :mod:`softarm.harvest` (beside :mod:`softarm.config`, which reads it from the
``[harvest]`` table of a configuration file); :mod:`softarm.harvest_config` re-exports it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.errors import ParameterError
from softarm.geometry import APPROACH_CONE_DEG

__all__ = ["FINE_END_RULES", "HarvestConfig"]

#: How fine positioning decides it has arrived (``HarvestConfig.fine_end_rule``):
#: "confidence", the measured error's upper confidence bound within ``fine_tolerance``;
#: "steps", ``settle_steps`` measured errors in a row within it (the rule before).
FINE_END_RULES = ("confidence", "steps")


@dataclass(frozen=True)
class HarvestConfig:
    """Parameters of :class:`~softarm.harvest.machine.harvest_machine.HarvestMachine`.

    Attributes:
        period: control period (s).
        approach: unit direction along which the gripper faces every berry (the bush
            lies along +Y of the base frame, section IV-F).
        approach_cone_deg: a placement planner may tilt the approach axis this far from
            ``approach`` when the arm cannot face the berry squarely.
        grasp_offset: how far ahead of the end-effector origin (m), along its z axis, a
            berry sits when it is between the fingers.
        standoff: pre-grasp distance (m) short of the grasp pose. Inside the 6 cm at which
            fig. 4 hands over to the eye-in-hand camera, so placement ends in its view.
        placement_tolerance: position error (m) that ends initial placement.
        angle_tolerance_deg: pointing error that ends initial placement.
        fine_tolerance: grasp-point-to-berry error (m) that ends fine positioning
            (section IV-E reports 0.75 ± 0.36 mm; 0.5 mm here, as the measured error
            stops the loop and the true one lands around it).
        grasp_workspace: error (m) the gripper still grasps at (±1 cm, section III-D);
            used only when fine positioning runs out of time or stalls on a joint limit
            (see ``reapproaches``).
        settle_steps: consecutive steps within tolerance before moving on (noise); in
            fine positioning under the "confidence" rule, the fewest measurements an
            estimate is made from.
        fine_end_rule: how fine positioning ends (``FINE_END_RULES``): "confidence"
            once the upper ``fine_confidence`` bound of the grasp error, from
            the mean and standard error of the last measurements (at least
            ``settle_steps``, at most ``fine_window``), is within ``fine_tolerance``: a
            noisy measurement of an arm on the berry ends within a few steps, a biased
            one does not end; "steps": ``settle_steps`` measured errors in a row within
            ``fine_tolerance`` (each value alone, however noisy; the default).
        fine_window: the most measurements (control steps with a new pose or berry fix)
            the "confidence" rule's estimate is made from (an integer >= 2).
        fine_confidence: the probability, in (0, 1), with which the true mean error lies
            under the bound the "confidence" rule compares with ``fine_tolerance``.
        fine_aim: with either rule, fine positioning ends only once the mean of the last
            ``settle_steps`` measured offsets of the grasp point is within this (m) of
            the berry as well, for up to ``end_rules.FINE_AIM_S`` (2 s) into the stage:
            the arm servoed on to the measured berry rather than stopped on the
            tolerance's edge; 0 (the default): the rule alone. In [0, fine_tolerance).
        marker_timeout: how long (s) the cube or the berry may stay unseen (beyond the
            locator's own hold of the last target) before MARKER_LOST.
        placement_timeout, fine_timeout, home_timeout: time budgets (s) of the stages.
        idle_timeout: time budget (s) of IDLE's ramp to the ready pose: every stage ends
            in bounded time, even on an arm its lag model never sees arrive.
        fine_budget: time (s) after which fine positioning settles for ``grasp_workspace``.
        stall_time: saturated for this long (s) without ``stall_progress`` (m) of
            improvement → UNREACHABLE.
        stall_progress: see ``stall_time``.
        reapproaches: how many times a berry the arm could not reach along its planned
            axis (saturated on the joint limits short of the grasp workspace) is tried
            again along another axis of the cone, after backing out home: the plan is
            the model's, and the true arm, a few % off it, may need a channel past its
            limit for one axis and not for another. In fine positioning a stall, or the
            end of ``fine_budget``, counts when it is farther than ``stall_progress``
            from the berry; nearer, or on the last attempt within ``grasp_workspace``,
            the gripper grasps. 0: no second attempt.
        ripeness_threshold: below it a grasped berry is unripe and released.
        home_speed: elongation rate (m/s) of the plan's feedforward and the open-loop
            moves to the ready pose: 0.045 m/s is 94.5 psi/s, inside the safety layer's
            default 100 psi/s rate limit.
        home_elongation: every actuator's elongation (m) at the ready pose (straight arm).
        transport_margin: gap (m) to the canes the model arm keeps on its way from where
            the lag model has it to each command while following a placement plan; a
            command that would leave less is not sent (the plan waits for the arm); where
            the arm is already nearer, the way may come only 1 mm nearer still. The
            planner's margin on the closed-loop approach, 1 cm.
        arrival_tolerance: an open-loop ramp ends once the lag model has every actuator
            within this (m) of the ramp's end (with a known lag; see docs/control.md §6).
        follow_blind_time: while following a plan, how long (s) its feedforward goes on,
            open loop and each command's way checked, through periods without a pose of
            the cube (a dropped frame; a fast move's pose the tracker refuses as a jump
            of more than 3 cm); then the arm waits for the next pose. 0: it waits at once.
        handover_tolerance: a plan's last leg hands the arm to the loop on the berry once
            its end is commanded and the lag model has every actuator within this (m) of
            it (with a known lag): the loop, closed through the lag model, counts the
            motion still in flight; ``arrival_tolerance`` waits for the arm itself.
        lead_cap: the most pre-compensation gain ``k`` of the regulators' lag (the
            regulators are told ``q + k (q - ŷ)``, within the safety layer's rate limit
            and pressure range; ``softarm._core.lead_gain``, docs/control.md §6); 0: no lead.
        plan_band: with it above 0, the placement planner moves each configuration it
            solves along its pose's null space to raise the least room of any actuator to
            its limits, up to this fraction of the range (``softarm.harvest.control.
            mid_band``; 0.5: as far as the pose allows). Off (0) by default: on the slow
            plant's fresh seeds 13 of 20 were slower with it, its quicker placement lost
            to fine positioning (docs/harvest-candidates.md, "Pre-grasp poses off the limits").
        play_skip: with it above 0, a channel whose fine-positioning command has moved
            the same way for this many periods inside the lag model's play band is put at
            the band's edge (``softarm.harvest.machine.stages.play_skip``): a slow
            plant's loop no longer creeps through its regulators' play for seconds; the
            nominal plant's 1.5 psi band is crossed before it counts. 0: off
            (docs/harvest.md, "The slow plant's defaults").
        near_standoff: for a berry fixed by its tag, the placement planner first tries a
            pre-grasp pose this near the grasp pose (where it is below ``standoff``),
            with the same cane margins, and falls back on ``standoff`` where none keeps
            them; fine positioning and the back-out then have that much less way to go.
            A markerless berry is always planned at ``standoff``: C2's detection needs
            that way to settle (in the row's sun, nearer, a grasp ended 8 mm off). 0:
            off (docs/harvest.md, "The slow plant's defaults").
    """

    period: float = 0.05
    approach: tuple[float, float, float] = (0.0, 1.0, 0.0)
    approach_cone_deg: float = APPROACH_CONE_DEG
    grasp_offset: float = 0.03
    standoff: float = 0.05
    placement_tolerance: float = 0.01
    angle_tolerance_deg: float = 5.0
    fine_tolerance: float = 0.0005
    grasp_workspace: float = 0.01
    settle_steps: int = 3
    fine_end_rule: str = "steps"
    fine_window: int = 20
    fine_confidence: float = 0.95
    fine_aim: float = 0.0
    marker_timeout: float = 1.0
    placement_timeout: float = 30.0
    fine_timeout: float = 20.0
    fine_budget: float = 12.0
    home_timeout: float = 10.0
    idle_timeout: float = 10.0
    stall_time: float = 3.0
    stall_progress: float = 0.002
    reapproaches: int = 1
    ripeness_threshold: float = 0.5
    home_speed: float = 0.045
    home_elongation: float = 0.0167
    arrival_tolerance: float = 0.001
    follow_blind_time: float = 0.15
    handover_tolerance: float = 0.001
    lead_cap: float = 1.5
    transport_margin: float = 0.01
    plan_band: float = 0.0
    play_skip: int = 5
    near_standoff: float = 0.03

    def __post_init__(self) -> None:
        for name in ("period", "standoff", "placement_tolerance", "fine_tolerance",
                     "grasp_workspace", "marker_timeout", "placement_timeout", "fine_timeout",
                     "fine_budget", "home_timeout", "idle_timeout", "stall_time", "home_speed",
                     "arrival_tolerance", "angle_tolerance_deg", "handover_tolerance"):  # fmt: skip
            value = _real(self, name)
            if not value > 0:
                raise ParameterError(f"{name} must be finite and > 0, got {value!r}")
        for name in ("grasp_offset", "stall_progress", "home_elongation", "transport_margin",
                     "follow_blind_time", "lead_cap", "fine_aim", "near_standoff"):  # fmt: skip
            value = _real(self, name)
            if not value >= 0:
                raise ParameterError(f"{name} must be finite and >= 0, got {value!r}")
        band = _real(self, "plan_band")
        if not 0.0 <= band <= 0.5:
            raise ParameterError(f"plan_band must be in [0, 0.5], got {band!r}")
        if self.lead_cap > 20.0:  # the actuator's bound on its lead
            raise ParameterError(f"lead_cap must be in [0, 20], got {self.lead_cap!r}")
        _real(self, "ripeness_threshold")
        cone = _real(self, "approach_cone_deg")
        if not 0 <= cone < 90:
            raise ParameterError(f"approach_cone_deg must be in [0, 90), got {cone!r}")
        a = self.approach
        if not (
            isinstance(a, tuple | list)
            and len(a) == 3
            and all(_is_real(x) and np.isfinite(x) for x in a)
            and abs(float(np.linalg.norm(a)) - 1.0) <= 1e-9
        ):
            raise ParameterError(f"approach must be a unit vector (3 numbers), got {a!r}")
        for name, least in (
            ("settle_steps", 1), ("reapproaches", 0), ("fine_window", 2), ("play_skip", 0),
        ):  # fmt: skip
            n = getattr(self, name)
            if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < least:
                raise ParameterError(f"{name} must be an integer >= {least}, got {n!r}")
        self._check_end_rule()

    def _check_end_rule(self) -> None:
        """``fine_end_rule`` one of FINE_END_RULES, ``fine_confidence`` in (0, 1),
        ``fine_aim`` under ``fine_tolerance``."""
        if self.fine_end_rule not in FINE_END_RULES:
            raise ParameterError(
                f"fine_end_rule must be one of {', '.join(FINE_END_RULES)}, "
                f"got {self.fine_end_rule!r}"
            )
        confidence = _real(self, "fine_confidence")
        if not 0.0 < confidence < 1.0:
            raise ParameterError(f"fine_confidence must be in (0, 1), got {confidence!r}")
        if not self.fine_aim < self.fine_tolerance:  # both checked finite already
            raise ParameterError(
                f"fine_aim must be in [0, fine_tolerance {self.fine_tolerance!r}), "
                f"got {self.fine_aim!r}"
            )

    @property
    def approach_axis(self) -> np.ndarray:
        """``approach`` as an array (3,)."""
        return np.asarray(self.approach, dtype=np.float64)


def _is_real(value: object) -> bool:
    return isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool)


def _real(config: HarvestConfig, name: str) -> float:
    """The field ``name`` if it is a finite number, else a ParameterError naming it."""
    value = getattr(config, name)
    if not (_is_real(value) and np.isfinite(value)):
        raise ParameterError(f"{name} must be a finite number, got {value!r}")
    return float(value)
