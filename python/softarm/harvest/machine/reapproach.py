"""The re-approach policy of one berry: after a stall, plan along another axis of the cone
or come back to the attempt that ended nearest the berry, and how close each attempt must
get to grasp (section III-D's ±1 cm; docs/harvest.md, "Re-approach").

:class:`~softarm.harvest.machine.harvest_machine.HarvestMachine` runs the attempts and
the way back between them; this object decides what comes next."""

from __future__ import annotations

from dataclasses import dataclass, field

from softarm.harvest.machine.interfaces import FloatArray
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.states import FaultReason

__all__ = ["Attempt", "Reapproach"]


@dataclass(frozen=True)
class Attempt:
    """An approach that stalled in fine positioning ``grasp_error`` (m) from the berry,
    inside the gripper's reach: its ``axis``, placement ``waypoints`` and pre-grasp
    ``standoff`` (m; None: ``[harvest] standoff``), to come back to."""

    grasp_error: float
    axis: FloatArray
    waypoints: tuple[FloatArray, ...]
    standoff: float | None = None


@dataclass
class Reapproach:
    """One berry's attempts: the axes ``tried``, the stall ``nearest`` the berry and the
    attempt being come ``back_to`` (None for a new plan). ``reapproaches`` new axes at
    most (none without a planner); ``stall_progress`` and ``grasp_workspace`` (m) from
    ``[harvest]``."""

    reapproaches: int
    stall_progress: float
    grasp_workspace: float
    has_planner: bool
    tried: list[FloatArray] = field(default_factory=list)
    nearest: Attempt | None = None
    back_to: Attempt | None = None

    def more(self) -> bool:
        """Whether a stall of this attempt may still be followed by a new axis."""
        return self.back_to is None and self.has_planner and len(self.tried) < self.reapproaches

    def grasp_within(self) -> float:
        """How near (m) this attempt's fine positioning must end to grasp past its
        budget: the stall rule's resolution while another axis is left to try; no worse
        than the nearest earlier attempt on the last new axis; else the gripper's reach."""
        if self.more():
            return self.stall_progress
        if self.back_to is None and self.nearest is not None:
            return self.nearest.grasp_error
        return self.grasp_workspace

    def after(
        self,
        fault: Fault,
        axis: FloatArray,
        waypoints: tuple[FloatArray, ...],
        standoff: float | None = None,
    ) -> str | None:
        """The attempt along ``axis`` (by ``waypoints``, to ``standoff``) ended in
        ``fault``: remember it if it stalled nearer than the nearest; why the berry is
        tried again (a new axis, or back to the nearest attempt), or None when it is not."""
        more = self.more()
        stalled = fault.reason is FaultReason.UNREACHABLE
        error = fault.grasp_error
        if stalled and error is not None and error <= self.grasp_workspace:
            if self.nearest is None or error < self.nearest.grasp_error:
                self.nearest = Attempt(error, axis, waypoints, standoff)
        if stalled and more:
            return "re-approach"
        if stalled and self.back_to is None and self.nearest is not None:
            self.back_to = self.nearest
            return "back to the nearest attempt"
        return None

    def again(self, axis: FloatArray) -> str:
        """Going again after :meth:`after` said why: the axis just left is tried; the
        transition's reason."""
        if self.back_to is None:
            self.tried.append(axis)
            return f"re-approach {len(self.tried)}: another axis"
        return f"back to the axis that ended {1e3 * self.back_to.grasp_error:.1f} mm off"
