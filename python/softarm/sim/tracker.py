"""A simulated pose tracker: camera-like noise on the end-effector pose, then the paper's
10 rad/s first-order low-pass filter (III, hardware), on position and on orientation
(the orientation is filtered on SO(3) through the rotation vector of the innovation)."""

from __future__ import annotations

import math

import numpy as np

from softarm import so3
from softarm.checks import FloatArray as F64
from softarm.errors import ParameterError


class PoseTracker:
    """Noisy, low-passed pose measurements.

    Args:
        rng: the random generator (determinism comes from its seed).
        position_noise: standard deviation of the position noise per axis (m).
        angle_noise: standard deviation of the rotation noise per axis (rad).
        cutoff: low-pass cut-off (rad/s); the paper uses 10.
    """

    def __init__(
        self,
        rng: np.random.Generator,
        position_noise: float = 1e-4,
        angle_noise: float = math.radians(0.1),
        cutoff: float = 10.0,
    ) -> None:
        for name, v in (("position_noise", position_noise), ("angle_noise", angle_noise)):
            if not (math.isfinite(v) and v >= 0.0):
                raise ParameterError(f"{name} = {v}: must be finite and >= 0")
        if not (math.isfinite(cutoff) and cutoff > 0.0):
            raise ParameterError(f"cutoff = {cutoff}: must be positive and finite")
        self.rng = rng
        self.position_noise = position_noise
        self.angle_noise = angle_noise
        self.cutoff = cutoff
        self.filtered: F64 | None = None

    def reset(self) -> None:
        """Forgets the filter state."""
        self.filtered = None

    def measure(self, true_pose: F64, dt: float) -> F64:
        """One measurement of ``true_pose`` taken ``dt`` seconds after the last."""
        noisy = true_pose.copy()
        noisy[:3, 3] += self.rng.normal(0.0, self.position_noise, 3)
        noisy[:3, :3] = so3.exp(self.rng.normal(0.0, self.angle_noise, 3)) @ true_pose[:3, :3]
        if self.filtered is None:
            self.filtered = noisy
            return noisy.copy()
        k = 1.0 - math.exp(-self.cutoff * dt)
        f = self.filtered
        out = np.eye(4)
        out[:3, 3] = f[:3, 3] + k * (noisy[:3, 3] - f[:3, 3])
        out[:3, :3] = so3.exp(k * so3.log(noisy[:3, :3] @ f[:3, :3].T)) @ f[:3, :3]
        self.filtered = out
        return out.copy()
