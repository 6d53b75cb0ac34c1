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

**What the data cannot say** (issue 26, items 11 to 13). Three things the fit used to
hide behind ``converged=True``:

* *outliers* (:mod:`~softarm.calibration.outliers`): a robust pass (soft-L1 loss) finds
  the samples far off every reasonable model; they are dropped, listed in
  ``Calibration.outliers``, and the final fit is plain least squares on the rest;
* *degenerate excitation* (:mod:`~softarm.calibration.identifiability`): when the data
  part of the Jacobian is rank deficient, the parameters of its null space are listed in
  ``Calibration.unidentifiable``, their standard deviations are infinite, and the fit is
  not converged;
* *edge inputs*: noise levels, the prior, commands and pose translations are bounded, so
  no residual can overflow.
"""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares

from softarm._core import SoftArm
from softarm.calibration.identifiability import Identifiability, identifiability
from softarm.calibration.metrics import PoseErrorStats, rotation_residuals
from softarm.calibration.model import ParameterMap
from softarm.calibration.outliers import outlier_indices
from softarm.calibration.result import Calibration
from softarm.checks import FloatArray as F64
from softarm.checks import numeric_array
from softarm.errors import (
    InputError,
    NonFiniteError,
    OutOfRangeError,
    ParameterError,
    PoseError,
    ShapeError,
)

__all__ = ["calibrate"]


_log = logging.getLogger(__name__)

#: Ranges of the weights (issue 26, item 13): a noise of 1e-300 or a prior of 1e-300
#: made every residual overflow and scipy raise. A nanometre / nanoradian is far below
#: any tracker, a metre / radian far above; a prior below 1e-6 is a constraint, not a
#: prior (``math.inf`` still turns it off).
NOISE_RANGE = (1e-9, 1.0)
PRIOR_RANGE = (1e-6, 1e6)
#: The largest command (m of elongation) and pose translation (m) taken: far beyond any
#: arm, small enough that no residual overflows (1e200 gave position_max_mm = inf).
MAX_COMMAND_M = 1.0
MAX_TRANSLATION_M = 100.0
#: The robust pass's soft-L1 scale, in noise levels: beyond it a residual pulls with a
#: bounded force.
ROBUST_SCALE = 3.0


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
    c = numeric_array(commands, "commands")
    if c.ndim != 2 or c.shape[1] != n:
        raise ShapeError(f"commands: expected shape (N, {n}), got {c.shape}")
    if not np.all(np.isfinite(c)):
        raise NonFiniteError("commands: contains NaN or inf")
    p = numeric_array(poses, "poses")
    if p.shape != (len(c), 4, 4):
        raise ShapeError(f"poses: expected shape ({len(c)}, 4, 4) to match commands, got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise NonFiniteError("poses: contains NaN or inf")
    _check_magnitudes(c, p)
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


def _check_magnitudes(c: F64, p: F64) -> None:
    if np.abs(c).max(initial=0.0) > MAX_COMMAND_M:
        raise OutOfRangeError(f"commands: elongations beyond +-{MAX_COMMAND_M:g} m")
    far = np.flatnonzero(np.abs(p[:, :3, 3]).max(axis=1) > MAX_TRANSLATION_M)
    if len(far):
        raise OutOfRangeError(f"poses[{far[0]}]: translation beyond {MAX_TRANSLATION_M:g} m")


def _in_range(name: str, v: float, lo: float, hi: float) -> float:
    ok = isinstance(v, int | float) and not isinstance(v, bool) and lo <= v <= hi
    if not ok:
        raise ParameterError(f"{name} = {v!r}: must be a number in [{lo:g}, {hi:g}]")
    return float(v)


class _Problem:
    """The weighted residuals and their Jacobian (see the module docstring) for the
    samples ``c`` (commands) and ``meas`` (poses)."""

    def __init__(self, pmap: ParameterMap, sp: float, sa: float, w_prior: float) -> None:
        self.pmap, self.sp, self.sa, self.w_prior = pmap, sp, sa, w_prior

    def samples(self, x: F64, c: F64, meas: F64) -> F64:
        """(N, 6) weighted residuals: position over its noise, rotation over its noise."""
        pred = self.pmap.arm(x).forward_batch(self.pmap.elongations(x, c))
        rp = (pred[:, :3, 3] - meas[:, :3, 3]) / self.sp
        return np.hstack([rp, rotation_residuals(pred, meas) / self.sa])

    def residuals(self, x: F64, c: F64, meas: F64) -> F64:
        return np.concatenate([self.samples(x, c, meas).ravel(), self.w_prior * x])

    def data_jacobian(self, x: F64, c: F64, meas: F64) -> F64:
        """The Jacobian of :meth:`samples`, flattened (6 N, parameters)."""
        pred, jp = self.pmap.pose_jacobian(x, c)
        jl = _inv_left_jacobian(rotation_residuals(pred, meas))
        rows = np.concatenate(
            [jp[:, :3] / self.sp, np.einsum("nij,njk->nik", jl, jp[:, 3:]) / self.sa], 1
        )
        return rows.reshape(-1, self.pmap.size)

    def jacobian(self, x: F64, c: F64, meas: F64) -> F64:
        return np.vstack([self.data_jacobian(x, c, meas), self.w_prior * np.eye(self.pmap.size)])

    def solve(self, c: F64, meas: F64, max_nfev: int, loss: str = "linear") -> Any:
        # Bounds keep every length positive; +-50 % is far outside any plausible arm.
        bound = np.full(self.pmap.size, 0.5)
        bound[3 : 4 * self.pmap.n_sections : 4] = math.pi / 4  # twists, rad
        return least_squares(
            self.residuals, np.zeros(self.pmap.size), jac=self.jacobian,
            bounds=(-bound, bound), method="trf", x_scale="jac", max_nfev=max_nfev,
            loss=loss, f_scale=ROBUST_SCALE, args=(c, meas),
        )  # fmt: skip


def _drop_outliers(problem: _Problem, c: F64, meas: F64, max_nfev: int) -> npt.NDArray[np.int64]:
    """Indices of the samples a robust fit finds outlying (see
    :mod:`softarm.calibration.outliers`)."""
    robust = problem.solve(c, meas, max_nfev, loss="soft_l1")
    out = outlier_indices(problem.samples(robust.x, c, meas))
    if len(out):
        _log.warning("calibrate: dropped %d outlying poses: indices %s", len(out), out.tolist())
    return out


def _parameter_std(sol: Any, size: int, ident: Identifiability, names: list[str]) -> F64:
    """Standard deviations from the Gauss-Newton covariance, scaled by the residuals' own
    variance (the noise levels may be mis-stated); infinite for the parameters the data
    leaves undetermined (the prior alone sets them)."""
    dof = max(sol.fun.size - size, 1)
    s2 = 2.0 * sol.cost / dof
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac) * s2
        std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:
        std = np.full(size, np.nan)
    lost = np.isin(names, ident.unidentifiable)
    return np.where(lost, np.inf, std)


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
        position_noise: the measurements' position noise per axis (m): residual weight,
            in [1e-9, 1].
        angle_noise: their rotation noise per axis (rad): residual weight, in [1e-9, 1].
        prior: standard deviation of the prior toward the nominal arm (relative for
            lengths and gains, rad for twists), in [1e-6, 1e6]; ``math.inf`` for plain
            least squares.
        max_nfev: most function evaluations of the solver.
        bias: also fit a constant bending bias per section (zero-mean actuator offsets,
            true elongation = gain x command + offset; 6 more parameters): the
            gravity-aware term for an arm that sags (docs/fidelity.md).

    Returns:
        The fit. Outlying samples are dropped and listed in ``outliers``; parameters the
        excitation cannot determine are listed in ``unidentifiable`` (with infinite
        standard deviations, and ``converged`` False).

    Raises:
        ShapeError: wrong shapes, or fewer samples (outliers dropped) than parameters.
        NonFiniteError: NaN or inf in ``commands`` or ``poses``.
        OutOfRangeError: a command beyond 1 m or a pose translation beyond 100 m.
        PoseError: a pose that is not a rigid transform.
        ParameterError: a noise or prior outside its range.
    """
    c, meas = _check_arrays(nominal_arm, commands, poses)
    sp = _in_range("position_noise", position_noise, *NOISE_RANGE)
    sa = _in_range("angle_noise", angle_noise, *NOISE_RANGE)
    sprior = math.inf if prior == math.inf else _in_range("prior", prior, *PRIOR_RANGE)
    if not (isinstance(max_nfev, int) and max_nfev > 0):
        raise ParameterError(f"max_nfev = {max_nfev!r}: must be a positive integer")
    pmap = ParameterMap(nominal_arm, bias=bool(bias))
    _enough(len(c), pmap.size, "")
    problem = _Problem(pmap, sp, sa, 0.0 if math.isinf(sprior) else 1.0 / sprior)
    outliers = _drop_outliers(problem, c, meas, max_nfev)
    keep = np.setdiff1d(np.arange(len(c)), outliers)
    _enough(len(keep), pmap.size, f" once {len(outliers)} outliers are dropped")
    c, meas = c[keep], meas[keep]
    sol = problem.solve(c, meas, max_nfev)
    x, names = sol.x, pmap.names()
    ident = identifiability(problem.data_jacobian(x, c, meas), names)
    message = str(sol.message)
    if not ident.complete:
        _log.warning("calibrate: %s", ident)
        message = f"{ident}; {message}"
    arm = pmap.arm(x)
    return Calibration(
        arm=arm,
        actuator_gain=pmap.gains(x),
        actuator_offset=pmap.offsets(x),
        fit=PoseErrorStats.of(arm.forward_batch(pmap.elongations(x, c)), meas),
        parameters=dict(zip(names, x.tolist(), strict=True)),
        parameter_std=dict(
            zip(names, _parameter_std(sol, pmap.size, ident, names).tolist(), strict=True)
        ),
        converged=bool(sol.success) and ident.complete,
        message=message,
        outliers=tuple(int(i) for i in outliers),
        unidentifiable=ident.unidentifiable,
    )


def _enough(samples: int, size: int, why: str) -> None:
    if samples < size:
        raise ShapeError(
            f"commands, poses: {samples} samples{why}, fewer than the {size} fitted parameters"
        )
