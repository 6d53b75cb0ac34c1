"""Pose errors between predicted and measured poses, and their summary statistics."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from softarm.checks import FloatArray as F64

__all__ = ["PoseErrorStats", "pose_errors", "rotation_residuals"]


def rotation_residuals(predicted: F64, measured: F64) -> F64:
    """Rotation vectors (N, 3) of ``R_pred R_meas^T`` (base frame, rad)."""
    rel = np.einsum("nij,nkj->nik", predicted[:, :3, :3], measured[:, :3, :3])
    result: F64 = Rotation.from_matrix(rel).as_rotvec()
    return result


def pose_errors(predicted: F64, measured: F64) -> tuple[F64, F64]:
    """Position errors (N,) in m and orientation errors (N,) in rad."""
    pos = np.linalg.norm(predicted[:, :3, 3] - measured[:, :3, 3], axis=1)
    ang = np.linalg.norm(rotation_residuals(predicted, measured), axis=1)
    return pos, ang


@dataclass(frozen=True)
class PoseErrorStats:
    """Median, 95th percentile and maximum of the position (mm) and orientation (deg)
    errors over ``samples`` poses."""

    samples: int
    position_median_mm: float
    position_p95_mm: float
    position_max_mm: float
    orientation_median_deg: float
    orientation_p95_deg: float
    orientation_max_deg: float

    @classmethod
    def of(cls, predicted: F64, measured: F64) -> PoseErrorStats:
        pos, ang = pose_errors(predicted, measured)
        mm, deg = 1e3 * pos, np.degrees(ang)
        return cls(
            samples=len(pos),
            position_median_mm=float(np.median(mm)),
            position_p95_mm=float(np.percentile(mm, 95)),
            position_max_mm=float(np.max(mm)),
            orientation_median_deg=float(np.median(deg)),
            orientation_p95_deg=float(np.percentile(deg, 95)),
            orientation_max_deg=float(np.max(deg)),
        )

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)

    def __str__(self) -> str:
        return (
            f"position median {self.position_median_mm:.3f} mm, "
            f"p95 {self.position_p95_mm:.3f} mm; orientation median "
            f"{self.orientation_median_deg:.3f} deg, p95 {self.orientation_p95_deg:.3f} deg "
            f"({self.samples} poses)"
        )
