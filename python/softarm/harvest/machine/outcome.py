"""How a stage of the harvest ends: a :class:`StageOutcome` when it hands over to the
next state, a :class:`Fault` when it cannot."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from softarm.checks import FloatArray
from softarm.errors import SoftarmError
from softarm.harvest.machine.states import FaultReason

__all__ = ["Ending", "Fault", "StageOutcome"]


class Fault(SoftarmError):
    """Raised inside a stage to enter the safe state for ``reason``. ``retreat_from``: the
    commanded elongations at which a closed loop gave up on the berry, the arm sound (a
    stall on the joint limits, a time-out): the machine backs out the way it came from
    there before it vents, and after a stall may re-approach. None: vent where it is.
    ``grasp_error``: in fine positioning, how far (m) the grasp point was from the berry
    when the loop gave up (the machine may come back to its nearest attempt); else None.

    A :class:`~softarm.errors.SoftarmError` like every error softarm raises: the machine
    catches it (:data:`~softarm.harvest.machine.harvest_machine.STAGE_ERRORS`), and one
    that escaped it would still be one clean line at the command line, not a traceback."""

    def __init__(
        self,
        reason: FaultReason,
        detail: str,
        retreat_from: FloatArray | None = None,
        grasp_error: float | None = None,
    ) -> None:
        super().__init__(detail)
        self.reason = reason
        self.retreat_from = retreat_from
        self.grasp_error = grasp_error


class Ending(StrEnum):
    """Why a closed-loop stage handed over (every way but a fault)."""

    #: Within the tolerances for ``settle_steps`` steps in a row (fine positioning under
    #: ``fine_end_rule = "confidence"``: the error's upper confidence bound within them).
    SETTLED = "settled"
    #: Fine positioning ran out of its budget inside the grasp workspace (±1 cm).
    BUDGET = "budget"
    #: Saturated on a joint limit without progress, but inside the grasp workspace.
    LIMIT_GRASP = "limit_grasp"
    #: Placed within the position tolerance; a joint limit holds the pointing.
    PLACEMENT_LIMIT = "placement_limit"
    #: Fine positioning lost the cube or the berry with the grasp point last measured
    #: inside the grasp workspace: the arm held still meanwhile.
    LOST_GRASP = "lost_grasp"


@dataclass(frozen=True)
class StageOutcome:
    """What a stage hands to the machine: the commanded elongations ``q`` it ended at,
    how it ended, the approach ``axis`` it used (a placement planner may tilt it), and the
    plan's ``waypoints`` (elongations) the arm came in by, for the way out."""

    q: FloatArray
    ending: Ending
    axis: FloatArray
    waypoints: tuple[FloatArray, ...] = field(default=())
