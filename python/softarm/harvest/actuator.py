"""The pressure actuator of the harvest loop: elongations (m) → psi → safety layer."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.errors import NonFiniteError
from softarm.hardware.pressure_map import ElongationMap
from softarm.hardware.safety import SafePressureBank

__all__ = ["SafeActuator"]

FloatArray = npt.NDArray[np.float64]


class SafeActuator:
    """Sends elongations through ``bank`` (a :class:`SafePressureBank`, which clamps,
    rate-limits and watches every command) using ``pressure_map`` (the paper's 1/2100 m
    per psi, section IV-A). Implements :class:`~softarm.harvest.interfaces.PressureActuator`.
    """

    def __init__(self, bank: SafePressureBank, pressure_map: ElongationMap | None = None) -> None:
        self.bank = bank
        self.pressure_map = pressure_map or ElongationMap(max_psi=bank.max_pressure)

    def send(self, q: FloatArray) -> None:
        """Command elongations ``q`` (m). A NaN raises before anything is sent."""
        q = np.asarray(q, dtype=np.float64)
        if not np.all(np.isfinite(q)):
            raise NonFiniteError(f"q must be finite, got {q.tolist()!r}")
        self.bank.set_pressures(self.pressure_map.to_psi(q))

    def vent(self, reason: str) -> None:
        """Vent every channel; the safety layer logs ``reason``."""
        self.bank.vent(reason)
