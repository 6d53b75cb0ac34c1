"""First-order low-pass filter of a pose on SE(3) (section II-C: 10 rad/s cutoff).

Position: p ← p + a (p_meas − p). Orientation: R ← R · exp(a · log(Rᵀ R_meas)), a geodesic
(slerp) step, so the filtered rotation stays on SO(3); filtering matrix entries would not.
With a = 1 − exp(−ω Δt) both are the exact discretisation of ẋ = ω (x_meas − x) for a
measurement held over Δt, whatever the frame rate.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm import so3
from softarm.errors import InputError
from softarm.vision._checks import FloatArray, as_pose, positive


class PoseLowPassFilter:
    """Low-pass filter with cutoff ``cutoff`` (rad/s; time constant 1/cutoff)."""

    def __init__(self, cutoff: float = 10.0) -> None:
        self.cutoff = positive(cutoff, "cutoff")
        self._pose: FloatArray | None = None
        self._time: float | None = None

    @property
    def pose(self) -> FloatArray | None:
        """The current filtered pose, or None before the first update."""
        return None if self._pose is None else self._pose.copy()

    def reset(self) -> None:
        """Forget the state; the next update starts from its measurement."""
        self._pose, self._time = None, None

    def update(self, measurement: npt.ArrayLike, time: float) -> FloatArray:
        """Feed ``measurement`` (4, 4) taken at ``time`` (s); return the filtered pose."""
        meas = as_pose(measurement, "measurement", tol=1e-5)
        t = float(time)
        if not np.isfinite(t):
            raise InputError(f"time must be finite, got {time!r}")
        if self._pose is None or self._time is None:
            self._pose, self._time = meas, t
            return meas.copy()
        dt = t - self._time
        if dt < 0:
            raise InputError(f"time must not decrease: got {t} after {self._time}")
        a = 1.0 - np.exp(-self.cutoff * dt)
        pose = np.eye(4)
        pose[:3, 3] = self._pose[:3, 3] + a * (meas[:3, 3] - self._pose[:3, 3])
        cur = self._pose[:3, :3]
        pose[:3, :3] = cur @ so3.exp(a * so3.log(cur.T @ meas[:3, :3]))
        self._pose, self._time = pose, t
        return pose.copy()
