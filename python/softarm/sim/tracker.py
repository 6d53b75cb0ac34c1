"""A simulated pose tracker: camera-like noise on the end-effector pose, then the paper's
10 rad/s first-order low-pass filter (III, hardware), on position and on orientation
(the orientation is filtered on SO(3) through the rotation vector of the innovation)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError

F64 = npt.NDArray[np.float64]


def exp_so3(w: F64) -> F64:
    """Rotation matrix of rotation vector ``w`` (Rodrigues)."""
    theta = float(np.linalg.norm(w))
    k = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if theta < 1e-12:
        return np.eye(3) + k
    a = math.sin(theta) / theta
    b = (1.0 - math.cos(theta)) / theta**2
    return np.eye(3) + a * k + b * (k @ k)


def log_so3(r: F64) -> F64:
    """Rotation vector of a rotation matrix (angles below pi)."""
    c = max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0))
    theta = math.acos(c)
    v = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    if theta < 1e-9:
        return 0.5 * v
    return theta / (2.0 * math.sin(theta)) * v


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
        noisy[:3, :3] = exp_so3(self.rng.normal(0.0, self.angle_noise, 3)) @ true_pose[:3, :3]
        if self.filtered is None:
            self.filtered = noisy
            return noisy.copy()
        k = 1.0 - math.exp(-self.cutoff * dt)
        f = self.filtered
        out = np.eye(4)
        out[:3, 3] = f[:3, 3] + k * (noisy[:3, 3] - f[:3, 3])
        out[:3, :3] = exp_so3(k * log_so3(noisy[:3, :3] @ f[:3, :3].T)) @ f[:3, :3]
        self.filtered = out
        return out.copy()
