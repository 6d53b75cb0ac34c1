"""The checked observation of one berry's harvest, the one owner of marker loss.

The vision (:class:`~softarm.harvest.machine.interfaces.Vision`) says what it sees and holds the
last berry fix while the berry is hidden (its own age limit, section III-D). How long the
harvest goes on without a cube pose or a berry fix before MARKER_LOST is decided here,
and only here: a :class:`BerryWatch` lives for one berry, is handed to every stage, and
keeps what :class:`~softarm.harvest.machine.harvest_machine.HarvestMachine` records into the berry's
result (control steps, fixes per camera, the last fix, the errors at the grasp), also
when a stage ends in a fault.
"""

from __future__ import annotations

import numpy as np

from softarm.errors import NonFiniteError
from softarm.harvest.machine.interfaces import (
    BerryTarget,
    CameraName,
    Clock,
    FloatArray,
    Observation,
    Vision,
)
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.states import FaultReason, HarvestState
from softarm.harvest.records.log import HarvestLog

__all__ = ["BerryWatch"]


class BerryWatch:
    """What the stages see of ``berry``, checked, and the step log.

    The clocks of a lost cube and a lost berry run from their last sighting, or from the
    last :meth:`restart` / :meth:`excuse_berry` (a stage that needed no berry, such as
    the open-loop ramp, must not count against the next one).
    """

    def __init__(
        self,
        vision: Vision,
        clock: Clock,
        berry: BerryTarget,
        log: HarvestLog,
        marker_timeout: float,
    ) -> None:
        self.vision, self.clock, self.berry, self.log = vision, clock, berry, log
        self.marker_timeout = marker_timeout
        self._pose_seen = self._fix_seen = clock.now()
        #: Control steps logged.
        self.steps = 0
        #: Observations with a berry fix, per source camera.
        self.cameras: dict[CameraName, int] = {}
        #: The last berry fix observed (None before the first).
        self.last_fix: FloatArray | None = None
        #: Grasp point to berry (m) and pointing error (rad) of the last step that
        #: recorded them, as the cameras measure them.
        self.grasp_errors: tuple[float, float] | None = None

    def restart(self) -> None:
        """Start both clocks of lost markers now."""
        self._pose_seen = self._fix_seen = self.clock.now()

    def excuse_berry(self, t: float) -> None:
        """The berry counts as seen at ``t`` at the latest (a stage starting at ``t``)."""
        self._fix_seen = max(self._fix_seen, t)

    def observe(self, need_fix: bool = True) -> Observation:
        """Read the vision now; check for NaN and for markers lost too long (the berry
        only if ``need_fix``). Without ``need_fix`` the vision is told so and spends
        nothing on the berry up close (no C2 frame for it); the fix it gives then, C1's
        or the held one, is counted in :attr:`cameras` as any other.

        Raises:
            NonFiniteError: a pose or berry position is not finite.
            Fault: MARKER_LOST.
        """
        t = self.clock.now()
        seen = self.vision.observe(t, need_fix)
        pose, fix = seen.pose, seen.fix
        if pose is not None:
            pose = np.asarray(pose, dtype=np.float64)
            if not np.all(np.isfinite(pose)):
                raise NonFiniteError("end-effector pose from the eye-to-hand camera is not finite")
            self._pose_seen = t
        elif t - self._pose_seen > self.marker_timeout:
            raise Fault(FaultReason.MARKER_LOST, f"cube not seen for {t - self._pose_seen:.2f} s")
        if fix is not None:
            if not np.all(np.isfinite(fix.position)):
                raise NonFiniteError(f"berry position from {fix.camera} is not finite")
            self._fix_seen = t
            self.last_fix = fix.position
            self.cameras[fix.camera] = self.cameras.get(fix.camera, 0) + 1
        elif need_fix and t - self._fix_seen > self.marker_timeout:
            raise Fault(FaultReason.MARKER_LOST, f"berry not seen for {t - self._fix_seen:.2f} s")
        return Observation(t, pose, fix)

    def blind(self) -> Observation:
        """Nothing read (an open-loop step): the time only."""
        return Observation(self.clock.now(), None, None)

    def record_grasp_errors(self, position: float, pointing: float) -> None:
        """Keep the errors at the grasp (m, rad) the result reports."""
        self.grasp_errors = (position, pointing)

    def log_step(
        self,
        stage: HarvestState,
        seen: Observation,
        q: FloatArray,
        goal: FloatArray | None,
        errors: tuple[float, float] | None,
        saturated: bool,
    ) -> None:
        """Log one control step of ``stage`` and count it."""
        self.steps += 1
        fix = seen.fix
        self.log.step(
            t=seen.t,
            state=stage,
            berry=self.berry.tag_id,
            q=q,
            pose=seen.pose,
            target=None if fix is None else fix.position,
            camera=None if fix is None else fix.camera,
            target_age_s=None if fix is None else fix.age,
            goal=None if goal is None else goal[:3, 3],
            position_error_m=None if errors is None else errors[0],
            orientation_error_rad=None if errors is None else errors[1],
            saturated=saturated,
        )
