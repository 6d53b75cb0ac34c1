"""Least-squares rigid registration of paired 3-D points (Arun / Umeyama, with the
reflection fix), as used for T_C1^Base and T_C2^EE in eq. (21)–(22) of the paper, which
cites Fitzpatrick et al. [34] for the point-registration error model."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softarm.errors import InputError, ShapeError
from softarm.vision._checks import FloatArray, as_array


@dataclass(frozen=True)
class RegistrationResult:
    """``transform`` (4, 4) maps source points onto target points (target ≈ T·source);
    ``residuals`` (N,) are the per-pair distances after registration (m) and ``rms`` their
    root mean square (the fiducial registration error, FRE)."""

    transform: FloatArray
    residuals: FloatArray
    rms: float


def register_points(
    source: npt.ArrayLike, target: npt.ArrayLike, weights: npt.ArrayLike | None = None
) -> RegistrationResult:
    """The rigid transform T minimising Σ wᵢ ‖target_i − T·source_i‖².

    ``source`` and ``target`` are (N, 3) with N ≥ 3 points that are not collinear. The
    rotation is a proper rotation (det +1) even when the best orthogonal fit would be a
    reflection (planar or noisy data). Raises :class:`~softarm.errors.ShapeError` for
    mismatched shapes and :class:`~softarm.errors.InputError` for degenerate points.
    """
    src = as_array(source, (None, 3), "source")
    dst = as_array(target, (None, 3), "target")
    if src.shape != dst.shape:
        raise ShapeError(
            f"source and target must have the same shape, got {src.shape} and {dst.shape}"
        )
    n = src.shape[0]
    if n < 3:
        raise ShapeError(f"source must have at least 3 points, got {n}")
    if weights is None:
        w = np.full(n, 1.0 / n)
    else:
        w = as_array(weights, (n,), "weights")
        if np.any(w < 0) or w.sum() <= 0:
            raise InputError("weights must be >= 0 with a positive sum")
        w = w / w.sum()
    mu_s, mu_t = w @ src, w @ dst
    a, b = src - mu_s, dst - mu_t
    cov = (b * w[:, None]).T @ a  # (3, 3) cross-covariance Σ wᵢ bᵢ aᵢᵀ
    u, _, vt = np.linalg.svd(cov)
    spread = np.linalg.svd(a, compute_uv=False)  # (3,) extent of the source cloud
    if spread[1] <= 1e-9 * max(float(spread[0]), 1e-300):
        raise InputError("source points are collinear (or coincident): rotation is undetermined")
    # Reflection fix (Umeyama 1991): flip the smallest singular direction if det < 0.
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    rot = u @ np.diag([1.0, 1.0, d]) @ vt
    out = np.eye(4)
    out[:3, :3] = rot
    out[:3, 3] = mu_t - rot @ mu_s
    res = np.linalg.norm(src @ rot.T + out[:3, 3] - dst, axis=1)
    return RegistrationResult(out, res, float(np.sqrt(np.mean(res**2))))
