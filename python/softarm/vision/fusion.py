"""Two-camera fusion for visual servoing (section III-D, fig. 4).

The end-effector pose comes from the eye-to-hand camera C1 (eq. 22):
T_base_ee = T_base_c1 · T_c1_ee. The berry is measured either by C1 directly, or by the
eye-in-hand camera C2 and carried to the base frame (eq. 21):
p_base = T_base_ee · T_ee_c2 · p_c2. Far from the berry C1 leads; once the tool is within
``handover_distance`` (6 cm in the paper) C2 leads, for fine control. When the berry is
hidden the most recent target is held, up to ``max_age`` seconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from softarm.errors import InputError, ParameterError
from softarm.vision._checks import FloatArray, as_array, as_pose, positive

Mode = Literal["eye_to_hand", "eye_in_hand"]
Source = Literal["eye_to_hand", "eye_in_hand", "held", "none"]


@dataclass(frozen=True)
class FusionEstimate:
    """One fused estimate: ``T_base_ee`` (None if unknown), ``target`` (3,) in the base
    frame (None if unknown), the ``source`` of the target, its ``target_age`` (s since it
    was measured; inf if never) and the ``mode`` (which camera leads) after this update."""

    T_base_ee: FloatArray | None
    target: FloatArray | None
    source: Source
    target_age: float
    mode: Mode


class CameraFusion:
    """Fuses eye-to-hand and eye-in-hand measurements into base-frame estimates.

    ``T_base_c1``: eye-to-hand camera in the base frame (registration, eq. 22).
    ``T_ee_c2``: eye-in-hand camera in the end-effector frame (hand-eye registration, eq. 21).
    ``tool_point``: the point (EE frame) whose distance to the target drives the
    hand-over; ``hysteresis`` (m) is added to ``handover_distance`` for the way back.
    ``ee_max_age`` bounds how long a lost end-effector pose is held.
    """

    def __init__(
        self,
        T_base_c1: npt.ArrayLike,
        T_ee_c2: npt.ArrayLike,
        handover_distance: float = 0.06,
        hysteresis: float = 0.01,
        max_age: float = 1.0,
        ee_max_age: float = 0.5,
        tool_point: npt.ArrayLike = (0.0, 0.0, 0.0),
    ) -> None:
        self.T_base_c1 = as_pose(T_base_c1, "T_base_c1")
        self.T_ee_c2 = as_pose(T_ee_c2, "T_ee_c2")
        self.handover_distance = positive(handover_distance, "handover_distance")
        if not np.isfinite(hysteresis) or hysteresis < 0:
            raise ParameterError(f"hysteresis must be >= 0, got {hysteresis!r}")
        self.hysteresis = float(hysteresis)
        self.max_age = positive(max_age, "max_age")
        self.ee_max_age = positive(ee_max_age, "ee_max_age")
        self.tool_point = as_array(tool_point, (3,), "tool_point")
        self.reset()

    def reset(self) -> None:
        """Back to eye-to-hand mode with nothing held."""
        self.mode: Mode = "eye_to_hand"
        self._ee: tuple[FloatArray, float] | None = None
        self._target: tuple[FloatArray, float] | None = None
        self._time: float | None = None

    def update(
        self,
        time: float,
        T_c1_ee: npt.ArrayLike | None = None,
        target_c1: npt.ArrayLike | None = None,
        target_c2: npt.ArrayLike | None = None,
    ) -> FusionEstimate:
        """Fuse this instant's measurements (None = not seen) taken at ``time`` (s)."""
        t = float(time)
        if not np.isfinite(t) or (self._time is not None and t < self._time):
            raise InputError(f"time must be finite and not decrease, got {time!r}")
        self._time = t
        if T_c1_ee is not None:
            self._ee = (self.T_base_c1 @ as_pose(T_c1_ee, "T_c1_ee", tol=1e-5), t)  # eq. (22)
        ee = self._ee[0] if self._ee and t - self._ee[1] <= self.ee_max_age else None
        fresh: dict[str, FloatArray] = {}
        if target_c1 is not None:
            p = as_array(target_c1, (3,), "target_c1")
            fresh["eye_to_hand"] = self.T_base_c1[:3, :3] @ p + self.T_base_c1[:3, 3]
        if target_c2 is not None and ee is not None:
            p = as_array(target_c2, (3,), "target_c2")
            t_base_c2 = ee @ self.T_ee_c2  # eq. (21): T_EE^Base T_C2^EE P^C2
            fresh["eye_in_hand"] = t_base_c2[:3, :3] @ p + t_base_c2[:3, 3]
        source, target = self._pick(fresh, t)
        if ee is not None and target is not None and self._switch(ee, target):
            source, target = self._pick(fresh, t)
        if source in fresh and target is not None:
            self._target = (target, t)
        age = 0.0 if source in fresh else (t - self._target[1] if self._target else np.inf)
        if target is None:
            source = "none"
        return FusionEstimate(
            None if ee is None else ee.copy(),
            None if target is None else target.copy(),
            source,
            float(age),
            self.mode,
        )

    def _pick(self, fresh: dict[str, FloatArray], t: float) -> tuple[Source, FloatArray | None]:
        """The target by preference for the current mode: leading camera, then (far from
        the berry only) the other camera, then the held target, then (close) the other."""
        lead: Source = self.mode
        other: Source = "eye_in_hand" if lead == "eye_to_hand" else "eye_to_hand"
        if lead in fresh:
            return lead, fresh[lead]
        if lead == "eye_to_hand" and other in fresh:
            return other, fresh[other]
        if self._target is not None and t - self._target[1] <= self.max_age:
            return "held", self._target[0]
        if other in fresh:
            return other, fresh[other]
        return "none", None

    def _switch(self, ee: FloatArray, target: FloatArray) -> bool:
        """Update the mode from the tool-to-target distance; True if it changed."""
        tool = ee[:3, :3] @ self.tool_point + ee[:3, 3]
        dist = float(np.linalg.norm(target - tool))
        old = self.mode
        if old == "eye_to_hand" and dist < self.handover_distance:
            self.mode = "eye_in_hand"
        elif old == "eye_in_hand" and dist > self.handover_distance + self.hysteresis:
            self.mode = "eye_to_hand"
        return self.mode != old
