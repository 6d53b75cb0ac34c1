"""``calibrate``: fit the arm's geometry and actuator gains to measured poses.

A weighted nonlinear least-squares problem solved by scipy's ``least_squares`` (trust
region reflective) with the analytic Jacobian of :mod:`softarm.calibration.model`:

* per sample, six residuals: the position error divided by the measurement's position
  noise and the rotation vector of ``R_model R_measured^T`` divided by its angle noise,
  so that a millimetre and a degree weigh by how well the tracker measures them;
* one prior residual per parameter, its deviation from nominal divided by ``prior``
  (relative for radii, rest lengths, offsets and gains; radians for twists).

**Identifiability.** With a full pose (position and orientation) every parameter has a
distinct signature, but some are only weakly apart: a section's three gains scaled up
together against its radius scaled up by the same factor leave the bending angle
unchanged and differ only by the extension (a few mm over the whole range); a straight
section's rest length and plate offset are the same straight piece and only bending
separates them. The prior fixes the gauge of such near-null directions at the nominal
values instead of letting noise pick them. It is weak (10 % by default, against 0.1 mm
noise per sample), so well-measured parameters are left to the data; the fitted
``parameter_std`` shows which directions the data pinned down.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares

from softarm._core import SoftArm
from softarm.calibration.metrics import PoseErrorStats, rotation_residuals
from softarm.calibration.model import ParameterMap
from softarm.calibration.result import Calibration
from softarm.errors import InputError, NonFiniteError, ParameterError, PoseError, ShapeError

__all__ = ["calibrate"]

F64 = npt.NDArray[np.float64]


def _inv_left_jacobian(phi: F64) -> F64:
    """Inverse left Jacobians (N, 3, 3) of SO(3) at rotation vectors ``phi`` (N, 3):
    log(exp(d) exp(phi)) = phi + J_l^-1(phi) d + O(d^2)."""
    theta = np.linalg.norm(phi, axis=1)
    k = np.zeros((len(phi), 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -phi[:, 2], phi[:, 1], -phi[:, 0]
    k -= np.transpose(k, (0, 2, 1))
    small = theta < 1e-6
    t = np.where(small, 1.0, theta)
    c = np.where(small, 1.0 / 12.0, 1.0 / t**2 - (1.0 + np.cos(t)) / (2.0 * t * np.sin(t)))
    return np.eye(3) - 0.5 * k + c[:, None, None] * (k @ k)


def _check_arrays(nominal_arm: Any, commands: Any, poses: Any) -> tuple[F64, F64]:
    if not isinstance(nominal_arm, SoftArm):
        raise InputError(f"nominal_arm: expected a softarm.SoftArm, got {type(nominal_arm)}")
    n = nominal_arm.n_actuators
    c = np.asarray(commands, dtype=np.float64)
    if c.ndim != 2 or c.shape[1] != n:
        raise ShapeError(f"commands: expected shape (N, {n}), got {c.shape}")
    if not np.all(np.isfinite(c)):
        raise NonFiniteError("commands: contains NaN or inf")
    p = np.asarray(poses, dtype=np.float64)
    if p.shape != (len(c), 4, 4):
        raise ShapeError(f"poses: expected shape ({len(c)}, 4, 4) to match commands, got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise NonFiniteError("poses: contains NaN or inf")
    bottom = np.abs(p[:, 3] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=1)
    r = p[:, :3, :3]
    ortho = np.abs(np.einsum("nij,nkj->nik", r, r) - np.eye(3)).max(axis=(1, 2))
    bad = np.flatnonzero((bottom > 1e-6) | (ortho > 1e-4) | (np.linalg.det(r) < 0.0))
    if len(bad):
        raise PoseError(
            f"poses[{bad[0]}]: not a rigid transform (last row [0, 0, 0, 1], orthonormal "
            f"rotation with det +1)"
        )
    return c, p


def _positive(name: str, v: float) -> float:
    if not (isinstance(v, int | float) and math.isfinite(v) and v > 0.0):
        raise ParameterError(f"{name} = {v!r}: must be a positive finite number")
    return float(v)


def calibrate(
    nominal_arm: SoftArm,
    commands: npt.ArrayLike,
    poses: npt.ArrayLike,
    *,
    position_noise: float = 1e-4,
    angle_noise: float = math.radians(0.1),
    prior: float = 0.1,
    max_nfev: int = 100,
    bias: bool = False,
) -> Calibration:
    """Fit per-section radius, rest length, plate offset and twist, and per-actuator
    gains (true elongation = gain x command), to measured end-effector poses.

    Args:
        nominal_arm: the starting model and the prior's centre.
        commands: (N, n) elongation commands (m) the poses were measured at.
        poses: (N, 4, 4) measured ``T_base_ee``.
        position_noise: the measurements' position noise per axis (m): residual weight.
        angle_noise: their rotation noise per axis (rad): residual weight.
        prior: standard deviation of the prior toward the nominal arm (relative for
            lengths and gains, rad for twists); ``math.inf`` for plain least squares.
        max_nfev: most function evaluations of the solver.
        bias: also fit a constant bending bias per section (zero-mean actuator offsets,
            true elongation = gain x command + offset; 6 more parameters): the
            gravity-aware term for an arm that sags (docs/fidelity.md).

    Raises:
        ShapeError: wrong shapes, or fewer samples than fitted parameters.
        NonFiniteError: NaN or inf in ``commands`` or ``poses``.
        PoseError: a pose that is not a rigid transform.
        ParameterError: a non-positive noise or prior.
    """
    c, meas = _check_arrays(nominal_arm, commands, poses)
    sp = _positive("position_noise", position_noise)
    sa = _positive("angle_noise", angle_noise)
    sprior = float(prior) if prior == math.inf else _positive("prior", prior)
    if not (isinstance(max_nfev, int) and max_nfev > 0):
        raise ParameterError(f"max_nfev = {max_nfev!r}: must be a positive integer")
    pmap = ParameterMap(nominal_arm, bias=bool(bias))
    if len(c) < pmap.size:
        raise ShapeError(
            f"commands, poses: {len(c)} samples, fewer than the {pmap.size} fitted parameters"
        )
    w_prior = 0.0 if math.isinf(sprior) else 1.0 / sprior

    def residuals(x: F64) -> F64:
        pred = pmap.arm(x).forward_batch(pmap.elongations(x, c))
        rp = (pred[:, :3, 3] - meas[:, :3, 3]) / sp
        ro = rotation_residuals(pred, meas) / sa
        return np.concatenate([np.hstack([rp, ro]).ravel(), w_prior * x])

    def jacobian(x: F64) -> F64:
        pred, jp = pmap.pose_jacobian(x, c)
        jl = _inv_left_jacobian(rotation_residuals(pred, meas))
        rows = np.concatenate([jp[:, :3] / sp, np.einsum("nij,njk->nik", jl, jp[:, 3:]) / sa], 1)
        return np.vstack([rows.reshape(-1, pmap.size), w_prior * np.eye(pmap.size)])

    # Bounds keep every length positive; +-50 % is far outside any plausible arm.
    bound = np.full(pmap.size, 0.5)
    bound[3 : 4 * pmap.n_sections : 4] = math.pi / 4  # twists, rad
    sol = least_squares(
        residuals, np.zeros(pmap.size), jac=jacobian, bounds=(-bound, bound),
        method="trf", x_scale="jac", max_nfev=max_nfev,
    )  # fmt: skip
    x = sol.x
    arm, gains, offsets = pmap.arm(x), pmap.gains(x), pmap.offsets(x)
    stats = PoseErrorStats.of(arm.forward_batch(pmap.elongations(x, c)), meas)
    # Parameter standard deviations from the Gauss-Newton covariance, scaled by the
    # residuals' own variance (the noise levels may be mis-stated).
    dof = max(sol.fun.size - pmap.size, 1)
    s2 = 2.0 * sol.cost / dof
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac) * s2
        std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:
        std = np.full(pmap.size, np.nan)
    return Calibration(
        arm=arm,
        actuator_gain=gains,
        actuator_offset=offsets,
        fit=stats,
        parameters=dict(zip(pmap.names(), x.tolist(), strict=True)),
        parameter_std=dict(zip(pmap.names(), std.tolist(), strict=True)),
        converged=bool(sol.success),
        message=str(sol.message),
    )
