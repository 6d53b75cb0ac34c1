"""The two maps at the pressure boundary: elongation (m) ↔ pressure (psi) ↔ voltage (V).

Inside softarm everything is SI; psi and volts exist only here and in the drivers.

* :class:`ElongationMap` — the actuator's length/pressure ratio measured in the
  redundancy paper (section IV-A, linear guide + optical encoder, 10→50 psi ramp):
  ``l / P = 1/2100 m per psi``. The map is linear through the origin. It is a fit over
  10–50 psi: below about 5 psi the real actuator barely elongates (paper, Fig. 9D).
* :class:`VoltageMap` — the command voltage of an SMC ITV1031-21N2BL4 proportional
  regulator driven 0–5 V by the NI analog output board (paper, section II-D).

  **Assumption (not verified against a datasheet here):** in SMC's ITV10x0 ordering
  code the digit after ``ITV10`` selects the set-pressure range, ``3`` = 0.5 MPa, and
  the regulator is linear from 0 V ↔ 0 MPa to full-scale voltage ↔ full-scale pressure.
  So the default is 0–5 V ↔ 0–0.5 MPa = 0–72.52 psi (gauge). The paper's highest
  command, 70 psi, fits inside it. Check the label of your regulators and set
  ``channels.full_scale_psi`` / ``channels.voltage_range`` in the TOML if they differ.

Both maps reject NaN/inf with :class:`~softarm.errors.NonFiniteError` and clamp into
their range by default; with ``clamp=False`` they raise
:class:`~softarm.errors.OutOfRangeError` instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import NonFiniteError, OutOfRangeError, ParameterError
from softarm.units import MAX_PSI, METRES_PER_PSI, PA_PER_PSI

__all__ = [
    "ITV1031_FULL_SCALE_PSI",
    "METRES_PER_PSI",
    "PA_PER_PSI",
    "ElongationMap",
    "VoltageMap",
]

ArrayLike = npt.ArrayLike

# PA_PER_PSI and METRES_PER_PSI are defined once in softarm.units and re-exported here.
#: Assumed full scale of the ITV1031 regulator: 0.5 MPa in psi (≈ 72.52).
ITV1031_FULL_SCALE_PSI = 0.5e6 / PA_PER_PSI


def _finite(name: str, value: ArrayLike) -> FloatArray:
    arr = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        raise NonFiniteError(f"{name} must be finite, got {arr.tolist()!r}")
    return arr


def _limit(name: str, arr: FloatArray, lo: float, hi: float, clamp: bool) -> FloatArray:
    if not clamp and (np.any(arr < lo) or np.any(arr > hi)):
        raise OutOfRangeError(f"{name} must lie in [{lo}, {hi}], got {arr.tolist()!r}")
    return np.clip(arr, lo, hi)


@dataclass(frozen=True)
class ElongationMap:
    """Linear actuator map ``l = metres_per_psi * P`` on ``P ∈ [0, max_psi]``.

    Args:
        max_psi: the highest pressure allowed (the elongation limit is
            ``max_psi * metres_per_psi``; 70 psi gives the arm's 0.0333 m).
        metres_per_psi: elongation per psi, the paper's 1/2100 m by default.
    """

    max_psi: float = MAX_PSI
    metres_per_psi: float = METRES_PER_PSI

    def __post_init__(self) -> None:
        if not (np.isfinite(self.max_psi) and self.max_psi > 0.0):
            raise ParameterError(f"max_psi must be finite and > 0, got {self.max_psi!r}")
        if not (np.isfinite(self.metres_per_psi) and self.metres_per_psi > 0.0):
            raise ParameterError(
                f"metres_per_psi must be finite and > 0, got {self.metres_per_psi!r}"
            )

    @property
    def max_elongation(self) -> float:
        """Elongation (m) at ``max_psi``."""
        return self.max_psi * self.metres_per_psi

    def to_psi(self, elongation: ArrayLike, *, clamp: bool = True) -> FloatArray:
        """Pressures (psi) that produce ``elongation`` (m), clamped to ``[0, max_psi]``."""
        psi = _finite("elongation", elongation) / self.metres_per_psi
        return _limit("elongation / metres_per_psi", psi, 0.0, self.max_psi, clamp)

    def to_elongation(self, psi: ArrayLike, *, clamp: bool = True) -> FloatArray:
        """Elongations (m) produced by ``psi``, the pressure clamped to ``[0, max_psi]``."""
        p = _limit("psi", _finite("psi", psi), 0.0, self.max_psi, clamp)
        return p * self.metres_per_psi


@dataclass(frozen=True)
class VoltageMap:
    """Linear regulator map from ``[0, full_scale_psi]`` onto ``[v_min, v_max]``.

    Args:
        full_scale_psi: the pressure the regulator outputs at ``v_max``.
        v_min: command voltage for 0 psi.
        v_max: command voltage for ``full_scale_psi``.
    """

    full_scale_psi: float = ITV1031_FULL_SCALE_PSI
    v_min: float = 0.0
    v_max: float = 5.0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.full_scale_psi) and self.full_scale_psi > 0.0):
            raise ParameterError(
                f"full_scale_psi must be finite and > 0, got {self.full_scale_psi!r}"
            )
        if not (np.isfinite(self.v_min) and np.isfinite(self.v_max) and self.v_min < self.v_max):
            raise ParameterError(
                f"voltage range must be finite with v_min < v_max, got "
                f"({self.v_min!r}, {self.v_max!r})"
            )

    @property
    def volts_per_psi(self) -> float:
        """Slope of the map."""
        return (self.v_max - self.v_min) / self.full_scale_psi

    def to_volts(self, psi: ArrayLike, *, clamp: bool = True) -> FloatArray:
        """Command voltages for ``psi``, the pressure clamped to ``[0, full_scale_psi]``."""
        p = _limit("psi", _finite("psi", psi), 0.0, self.full_scale_psi, clamp)
        # Clip again: rounding must never push a command outside the board's range.
        return np.clip(self.v_min + p * self.volts_per_psi, self.v_min, self.v_max)

    def to_psi(self, volts: ArrayLike, *, clamp: bool = True) -> FloatArray:
        """Pressures for command (or monitor) voltages, clamped to ``[v_min, v_max]``."""
        v = _limit("volts", _finite("volts", volts), self.v_min, self.v_max, clamp)
        return (v - self.v_min) / self.volts_per_psi
