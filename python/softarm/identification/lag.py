"""Regulator lag and dead time per channel from the pressure readings.

Model: ``tau dp/dt = u(t - D) - p`` with ``u`` the command the safety layer sent, held
over each control period (a first-order regulator behind a pure delay ``D``, the hose).
For a piecewise-constant command and ``D = j dt + f`` (``0 <= f < dt``) the exact
discrete solution over one period is linear in the two commands that the delayed input
spans::

    p[k] = a p[k-1] + a2 (1 - a1) c[k-j-1] + (1 - a2) c[k-j],
    a1 = exp(-f / tau),  a2 = exp(-(dt - f) / tau),  a = a1 a2,

so a whole channel's response is one ``scipy.signal.lfilter`` call and ``(tau, D)``
is a two-parameter least squares (``scipy.optimize.least_squares``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import lfilter

from softarm.checks import FloatArray as F64

__all__ = ["LagFit", "fit_lag", "simulate_lag"]


#: Bounds of the search (s): a time constant below dt/50 cannot be told from none at the
#: control rate; a dead time beyond 1 s would mean a broken line.
TAU_BOUNDS = (1e-3, 30.0)
DEAD_BOUNDS = (0.0, 1.0)


@dataclass(frozen=True)
class LagFit:
    """One channel's fit: time constant and dead time (s), RMS residual (psi)."""

    tau_s: float
    dead_time_s: float
    rms_psi: float


def simulate_lag(
    sent: F64, dt: float, tau: float, dead: float, p0: float, c0: float | None = None
) -> F64:
    """Pressures after each period for commands ``sent`` (one channel), see module doc."""
    c_before = p0 if c0 is None else c0
    j = math.floor(dead / dt + 1e-12)
    f = dead - j * dt
    a1, a2 = math.exp(-f / tau), math.exp(-(dt - f) / tau)
    a = a1 * a2
    padded = np.concatenate([np.full(j + 1, c_before), sent])
    k = np.arange(len(sent))
    c_now = padded[k + 1]  # c[k - j]
    c_prev = padded[k]  # c[k - j - 1]
    v = a2 * (1.0 - a1) * c_prev + (1.0 - a2) * c_now
    out, _ = lfilter([1.0], [1.0, -a], v, zi=[a * p0])
    return np.asarray(out)


def fit_lag(sent: F64, pressure: F64, dt: float, p0: float, c0: float) -> LagFit:
    """Fit ``(tau, D)`` of one channel to its pressure readings."""
    sent = np.asarray(sent, dtype=np.float64)
    pressure = np.asarray(pressure, dtype=np.float64)
    ok = np.isfinite(pressure)

    def residual(x: F64) -> F64:
        model = simulate_lag(sent, dt, math.exp(x[0]), x[1], p0, c0)
        return (model - pressure)[ok]

    lo = [math.log(TAU_BOUNDS[0]), DEAD_BOUNDS[0]]
    hi = [math.log(TAU_BOUNDS[1]), DEAD_BOUNDS[1]]
    # The residual is not smooth in D at multiples of dt (a new command enters the
    # window) and has flat stretches in tau: start the local solver from the best point
    # of a coarse grid.
    grid = [(t, d * dt) for t in (0.02, 0.08, 0.3, 1.0, 3.0) for d in (0.25, 1.5, 4.5)]
    costs = [float(np.sum(residual(np.array([math.log(t), d])) ** 2)) for t, d in grid]
    tau0, dead0 = grid[int(np.argmin(costs))]
    best = least_squares(residual, [math.log(tau0), dead0], bounds=(lo, hi))
    rms = math.sqrt(2.0 * best.cost / max(1, int(ok.sum())))
    return LagFit(math.exp(best.x[0]), float(best.x[1]), rms)
