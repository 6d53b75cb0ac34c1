"""Actuator gains (m/psi) and hysteresis per channel from tracked poses.

The tracker sees the end-effector pose ``T = F_geom(m ⊙ e)`` where ``e`` is each
actuator's pressure after its play operator (band ``w``) and ``m`` its elongation per
psi. Per channel, a pose change only tells ``J_i(q) m_i`` (the Jacobian column of eq.
4-6 times the gain): with the nominal geometry the gain would absorb every geometry
error (a 3 % larger radius reads as a 3 % weaker actuator). So the fit estimates the
geometry too — per section the radius, rest length, plate offset and twist, as
``softarm.Section`` takes them — jointly with the gains and the band widths, from holds
spread over the workspace (:mod:`softarm.identification.protocol`). The residuals are
the tracker's position and rotation errors of the constant-curvature model (eq. 3),
evaluated by the core's batch forward kinematics; ``scipy.optimize.least_squares``
solves it.

What a pose can and cannot tell:

* extension of a section (all three actuators) moves the tip along the arc; bending
  rotates it by an angle ∝ differential elongation / radius. A common gain of a section
  and its radius are therefore separable only through the extension, and the rest
  length only through how the bending scales with length: with poses spread over the
  workspace they are, with poses near one configuration they are not.
* the hysteresis shows as the pose difference between approaching the same pressure
  from above and from below (phase 2 of the protocol), the gain as the pose change per
  psi: the band width in psi is their ratio, independent of the geometry to first order.
* The play state depends on the band width itself; the fit alternates between replaying
  the operator on the measured pressures with the current widths and solving with the
  play states fixed (the widths then enter linearly), until the states stop changing.

The tracker's low-pass filter (cut-off known, the paper's 10 rad/s) is applied to the
predicted poses of the whole run, so that holds that end before the pose has fully
settled still fit (half a second after a 50 psi move the filtered pose still trails by
about 1 mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares
from scipy.signal import lfilter

from softarm._core import Section, SoftArm
from softarm.checks import FloatArray as F64
from softarm.identification.record import Recording

__all__ = [
    "KinematicFit",
    "filter_gain",
    "fit_kinematics",
    "play_states",
    "pose_residual",
    "tracked",
]


#: Residual scales: the tracker's noise per axis (0.1 mm, 0.1 deg; paper III).
SIGMA_POSITION = 1e-4
SIGMA_ANGLE = math.radians(0.1)
#: Samples at the end of each hold that enter the fit (0.2 s at 20 Hz).
WINDOW = 4


@dataclass(frozen=True)
class KinematicFit:
    """The fitted gains, band widths and geometry, with standard errors."""

    metres_per_psi: F64
    hysteresis_psi: F64
    metres_per_psi_std: F64
    hysteresis_psi_std: F64
    arm: SoftArm
    rms_position_m: float
    rms_angle_rad: float
    samples: int
    geometry_fitted: bool


def play_states(pressure: F64, p0: F64, width: F64) -> F64:
    """Replay the play operator on ``pressure`` (K, n) from output ``p0``; returns the
    normalised state ``z = (y - p) / (w / 2)`` in [-1, 1] (0 where ``w = 0``)."""
    y = np.asarray(p0, dtype=np.float64).copy()
    half = 0.5 * np.asarray(width, dtype=np.float64)
    out = np.empty_like(pressure)
    for k in range(len(pressure)):
        y = np.clip(y, pressure[k] - half, pressure[k] + half)
        out[k] = y
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(half > 0.0, (out - pressure) / np.where(half > 0, half, 1.0), 0.0)
    return np.clip(z, -1.0, 1.0)


def _arm(nominal: SoftArm, geom: F64) -> SoftArm:
    # A trial step of the solver may leave the physical range: clip the log-scales to a
    # factor of e (any real arm is far inside) so that every trial is a valid arm.
    g = np.clip(geom.reshape(-1, 4), -1.0, 1.0)
    return SoftArm(
        [
            Section(
                radius=s.radius * math.exp(g[i, 0]),
                rest_length=s.rest_length * math.exp(g[i, 1]),
                lower=s.lower,
                upper=2.0 * s.upper + 1e-3,  # the fit never checks limits
                offset=s.offset * math.exp(g[i, 2]),
                twist=s.twist + g[i, 3],
            )
            for i, s in enumerate(nominal.sections)
        ]
    )


def _vee_skew(r: F64) -> F64:
    """Rotation vectors of nearly-identity rotations (N, 3, 3), to first order."""
    return 0.5 * np.stack(
        [r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]], axis=1
    )


def filter_gain(rec: Recording) -> float:
    """The tracker filter's gain per period (1: no filter)."""
    return 1.0 - math.exp(-rec.pose_cutoff * rec.period) if rec.pose_cutoff else 1.0


def tracked(arm: SoftArm, q: F64, keep: float) -> F64:
    """Tracker readings (K, 4, 4) for elongations ``q`` (K + 1, n), whose first row is
    the state before the first sample: the poses, low-passed like the tracker does. The
    rotation block is filtered element-wise, which is the SO(3) filter to first order in
    the (small) innovation of one period."""
    raw = arm.forward_batch(q)
    if keep >= 1.0:
        return raw[1:]
    flat = raw.reshape(len(raw), 16)
    out, _ = lfilter([keep], [1.0, -(1.0 - keep)], flat[1:], axis=0, zi=(1 - keep) * flat[:1])
    return np.asarray(out).reshape(-1, 4, 4)


def pose_residual(pred: F64, measured: F64) -> F64:
    """Position (per 0.1 mm) and rotation (per 0.1 deg) errors, flattened."""
    dp = (pred[:, :3, 3] - measured[:, :3, 3]) / SIGMA_POSITION
    rot = measured[:, :3, :3] @ np.transpose(pred[:, :3, :3], (0, 2, 1))
    da = _vee_skew(rot) / SIGMA_ANGLE
    return np.concatenate([dp, da], axis=1).ravel()


def _fitted_samples(rec: Recording) -> npt.NDArray[np.intp]:
    """The samples that enter the fit: the last ``WINDOW`` of every hold marked ``fit``
    (the arm has settled there), less those where the tracker lost the arm."""
    idx = np.array(
        [k for h in rec.holds if h.fit for k in range(max(h.start, h.end - WINDOW), h.end)]
    )
    valid = np.isfinite(rec.pose[idx]).all(axis=(1, 2))
    result: npt.NDArray[np.intp] = idx[valid]
    return result


@dataclass(frozen=True)
class _Problem:
    """The least-squares problem of one recording. The unknowns ``x`` are, in order, the
    geometry's log-scales and twists (``n_geom``, 0 when the geometry is not fitted), the
    log gains (``n``) and the band widths (``n``)."""

    nominal: SoftArm
    pressure: F64  # (upto + 1, n): the state before the first sample, then every sample
    idx: npt.NDArray[np.intp]  # the samples fitted
    measured: F64  # their tracked poses
    m0: float  # the recording's nominal elongation per psi
    n: int  # channels
    n_geom: int
    keep: float  # the tracker filter's gain per period

    @classmethod
    def of(cls, rec: Recording, nominal: SoftArm, fit_geometry: bool) -> _Problem:
        """The problem of ``rec``'s fitted samples. Every sample up to the last one fitted
        is predicted: the tracker's filter needs the history of the predicted poses, not
        only the fitted instants."""
        idx = _fitted_samples(rec)
        upto = int(idx.max()) + 1
        return cls(
            nominal=nominal,
            pressure=np.vstack([rec.pressure_before[None, :], rec.pressure[:upto]]),
            idx=idx,
            measured=rec.pose[idx],
            m0=rec.metres_per_psi,
            n=rec.pressure.shape[1],
            n_geom=4 * nominal.n_sections if fit_geometry else 0,
            keep=filter_gain(rec),
        )

    def unpack(self, x: F64) -> tuple[F64, F64, F64]:
        """(geometry, gains, band widths) of ``x``; the geometry is zero when not fitted.
        Log-scales keep lengths and gains positive; the play band is |w|."""
        n, n_geom = self.n, self.n_geom
        geom = np.zeros(4 * self.nominal.n_sections)
        geom[:n_geom] = x[:n_geom]
        return geom, np.exp(x[n_geom : n_geom + n]), np.abs(x[n_geom + n :])

    def residual(self, x: F64, z: F64) -> F64:
        """The tracker's errors (:func:`pose_residual`) of the poses ``x`` predicts with
        the play states ``z`` held fixed."""
        geom, gain, w = self.unpack(x)
        q = self.m0 * gain * (self.pressure + 0.5 * z * w)
        predicted: F64 = tracked(_arm(self.nominal, geom), q, self.keep)[self.idx]
        return pose_residual(predicted, self.measured)


def _solve(problem: _Problem, x: F64, scale: F64, max_rounds: int) -> tuple[Any, F64]:
    """Solves ``problem`` from ``x`` (updated in place); returns the last solution and the
    play states it was solved with.

    The gains and bands are solved first with the nominal geometry, which keeps the first
    geometry steps out of far-away minima when the plant is far from nominal; then
    everything. In each stage the play states are replayed with the current widths and
    the widths solved with the states fixed, until the states stop changing."""
    pressure = problem.pressure
    z_prev = None
    sol = None
    for stage in ("gains", "all"):
        active = np.arange(problem.n_geom, len(x)) if stage == "gains" else np.arange(len(x))
        z_prev = None
        for _ in range(max_rounds):
            z = play_states(pressure, pressure[0], problem.unpack(x)[2])
            if z_prev is not None and np.max(np.abs(z - z_prev)) < 1e-3:
                break
            z_prev = z

            def sub(xa: F64, z: F64 = z, active: npt.NDArray[np.intp] = active) -> F64:
                full = x.copy()
                full[active] = xa
                return problem.residual(full, z)

            sol = least_squares(sub, x[active], method="lm", x_scale=scale[active])
            x[active] = sol.x
        if problem.n_geom == 0:
            break
    assert sol is not None and z_prev is not None
    return sol, z_prev


def _standard_errors(sol: Any, n_params: int) -> F64:
    """Standard errors from the Gauss-Newton covariance, scaled by the residual variance."""
    jac = sol.jac
    dof = max(1, len(sol.fun) - n_params)
    cov = np.linalg.pinv(jac.T @ jac) * (2.0 * sol.cost / dof)
    result: F64 = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return result


def fit_kinematics(
    rec: Recording,
    nominal: SoftArm,
    *,
    fit_geometry: bool = True,
    width0: float = 1.0,
    max_rounds: int = 4,
) -> KinematicFit:
    """Fit gains, band widths and (``fit_geometry``) the geometry to ``rec``'s holds."""
    problem = _Problem.of(rec, nominal, fit_geometry)
    n, n_geom, m0 = problem.n, problem.n_geom, problem.m0
    x = np.concatenate([np.zeros(n_geom), np.zeros(n), np.full(n, width0)])
    # Typical sizes (a few % of geometry and gain, a psi of band) set the trust region.
    scale = np.concatenate([np.full(n_geom, 0.03), np.full(n, 0.03), np.full(n, 1.0)])
    sol, z = _solve(problem, x, scale, max_rounds)
    geom, gain, w = problem.unpack(x)
    std = _standard_errors(sol, len(x))
    r = problem.residual(x, z).reshape(-1, 6)
    rms_p = float(np.sqrt(np.mean(np.sum(r[:, :3] ** 2, axis=1)))) * SIGMA_POSITION
    rms_a = float(np.sqrt(np.mean(np.sum(r[:, 3:] ** 2, axis=1)))) * SIGMA_ANGLE
    return KinematicFit(
        metres_per_psi=m0 * gain,
        hysteresis_psi=w,
        metres_per_psi_std=m0 * gain * std[n_geom : n_geom + n],
        hysteresis_psi_std=std[n_geom + n :],
        arm=_arm(nominal, geom),
        rms_position_m=rms_p,
        rms_angle_rad=rms_a,
        samples=len(problem.idx),
        geometry_fitted=fit_geometry,
    )
