"""The inverse of the actuators' play hysteresis, in the pressure domain.

A pneumatic muscle's braid friction gives a play (backlash) loop between pressure and
length: the length follows the pressure only once the pressure has moved half the band
``w`` past it, ``y = clip(y_prev, p - w/2, p + w/2)`` (:mod:`softarm.sim.hysteresis`).
Commanded ``p = y* + s w/2`` with ``s`` the sign of the last motion, the actuator's
length settles at ``y*`` exactly; when the wanted pressure reverses, the command jumps
across the band (``w``) instead of the loop integrating its way across it, which is what
slows a closed loop behind play (docs/control.md, section 6).

The direction flips only after the wanted pressure has moved ``deadband`` psi back from
its extreme since the last flip: sensor noise on a settled loop would otherwise make the
command jump across the band every period. Within ``deadband`` the length may be off by
at most ``deadband`` psi of elongation.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError, ShapeError

__all__ = ["PlayInverse"]

FloatArray = npt.NDArray[np.float64]


class PlayInverse:
    """Backlash inverse of band widths ``width_psi`` (one per channel).

    Args:
        width_psi: the play band of each channel (psi, >= 0), e.g. an identified
            ``hysteresis_psi``.
        deadband: psi the wanted pressure must move back before the direction flips.
    """

    def __init__(self, width_psi: npt.ArrayLike, deadband: float = float(__import__("os").environ.get("DB", "0.05"))) -> None:
        w = np.asarray(width_psi, dtype=np.float64)
        if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise ParameterError(f"width_psi: must be a 1-D array of finite values >= 0, got {w!r}")
        if not (np.isfinite(deadband) and deadband >= 0):
            raise ParameterError(f"deadband = {deadband!r}: must be finite and >= 0")
        self.width = w
        self.deadband = float(deadband)
        self.reset()

    def reset(self) -> None:
        """Vented: every actuator at its lowest length, the next motion is upwards."""
        self._sign = np.ones_like(self.width)
        self._extreme = np.zeros_like(self.width)

    @property
    def offset(self) -> FloatArray:
        """What is added to the wanted pressure now (psi)."""
        return 0.5 * self.width * self._sign

    def command(self, wanted_psi: npt.ArrayLike) -> FloatArray:
        """The pressures to command (psi) for the actuators to settle at ``wanted_psi``."""
        p = np.asarray(wanted_psi, dtype=np.float64)
        if p.shape != self.width.shape:
            raise ShapeError(f"wanted_psi: expected shape {self.width.shape}, got {p.shape}")
        up = self._sign > 0
        flip = np.where(up, p < self._extreme - self.deadband, p > self._extreme + self.deadband)
        self._sign = np.where(flip, -self._sign, self._sign)
        up = self._sign > 0
        self._extreme = np.where(
            flip, p, np.where(up, np.maximum(self._extreme, p), np.minimum(self._extreme, p))
        )
        return p + self.offset
