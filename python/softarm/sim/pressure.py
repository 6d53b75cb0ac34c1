"""Pressure side of the simulated plant: the elongation <-> pressure map of IV-A
(1/2100 m per psi), saturation at 0 and the maximum pressure, and first-order pressure
dynamics of the regulators."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray as F64
from softarm.errors import ParameterError

# The map's constants are defined once in softarm.units; re-exported here for the plant.
from softarm.units import MAX_PSI, METRES_PER_PSI

__all__ = ["MAX_PSI", "METRES_PER_PSI", "PressureDynamics", "to_metres", "to_psi"]


def to_psi(q: npt.ArrayLike, metres_per_psi: float = METRES_PER_PSI) -> F64:
    """Elongations (m) -> pressures (psi), unclamped (may be negative: infeasible)."""
    return np.asarray(q, dtype=np.float64) / metres_per_psi


def to_metres(p: npt.ArrayLike, metres_per_psi: float = METRES_PER_PSI) -> F64:
    """Pressures (psi) -> elongations (m)."""
    return np.asarray(p, dtype=np.float64) * metres_per_psi


class PressureDynamics:
    """First-order lag ``tau dp/dt = p_cmd - p`` with the command saturated to
    ``[0, max_psi]``, integrated exactly for piecewise-constant commands."""

    def __init__(self, n: int, tau: float = 0.08, max_psi: float = MAX_PSI) -> None:
        if not (math.isfinite(tau) and tau > 0.0):
            raise ParameterError(f"tau = {tau}: must be positive and finite")
        if not (math.isfinite(max_psi) and max_psi > 0.0):
            raise ParameterError(f"max_psi = {max_psi}: must be positive and finite")
        self.tau = tau
        self.max_psi = max_psi
        self.pressure = np.zeros(n)

    def saturate(self, p_cmd: npt.ArrayLike) -> F64:
        """The command the regulators can realise: clamped to ``[0, max_psi]``."""
        return np.clip(np.asarray(p_cmd, dtype=np.float64), 0.0, self.max_psi)

    def advance(self, p_cmd: npt.ArrayLike, dt: float) -> F64:
        """Holds ``p_cmd`` (saturated) for ``dt`` seconds; returns the new pressures."""
        target = self.saturate(p_cmd)
        k = 1.0 - math.exp(-dt / self.tau)
        self.pressure = self.pressure + k * (target - self.pressure)
        return self.pressure.copy()
