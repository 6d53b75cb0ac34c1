"""Simulated backends: the hardware protocols on top of a simulated plant.

The simulated arm and the synthetic cameras live in :mod:`softarm.sim`; these classes
talk to them only through the small interfaces below, so either side can change.

* pressures: any object with ``command_pressures(psi)`` and ``pressures()`` —
  :class:`PressurePlant`. :class:`IdealPlant` is a stand-in whose pressures follow the
  command with an optional first-order lag.
* cameras: any zero-argument callable returning a BGR ``uint8`` image ``(h, w, 3)`` or
  ``None`` (a dropped frame).

Every simulated device has a :class:`Faults` object whose fields inject failures:
``disconnected`` (calls raise HardwareUnavailableError), ``error`` (calls raise it) and
``nan`` (readings come back NaN, to exercise the consumer's checks).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import HardwareError, HardwareUnavailableError, ShapeError
from softarm.hardware.pressure_map import ITV1031_FULL_SCALE_PSI

__all__ = [
    "Faults",
    "IdealPlant",
    "PressurePlant",
    "SimulatedCamera",
    "SimulatedGripper",
    "SimulatedPressureBank",
    "SimulatedRipenessSensor",
]

Image = npt.NDArray[np.uint8]


class PressurePlant(Protocol):
    """What a simulated arm must offer to be driven by :class:`SimulatedPressureBank`."""

    def command_pressures(self, psi: FloatArray) -> None:
        """Receive the regulator set-points (psi), shape ``(channels,)``."""
        ...

    def pressures(self) -> FloatArray:
        """The actuator pressures now (psi), shape ``(channels,)``."""
        ...


@dataclass
class Faults:
    """Fault injection switches shared by the simulated devices (see module docstring)."""

    disconnected: bool = False
    error: HardwareError | None = None
    nan: bool = False

    def check(self, device: str) -> None:
        """Raise the injected fault, if any, for an operation on ``device``."""
        if self.disconnected:
            raise HardwareUnavailableError(f"{device}: simulated disconnect")
        if self.error is not None:
            raise self.error


class IdealPlant:
    """Pressures that follow the command, instantly or with time constant ``tau_s``
    advanced by :meth:`advance`. A stand-in when the simulated arm is not wanted."""

    def __init__(self, channels: int = 9, tau_s: float = 0.0) -> None:
        self._target = np.zeros(channels)
        self._p = np.zeros(channels)
        self._tau = tau_s

    def command_pressures(self, psi: FloatArray) -> None:
        """Set the target pressures."""
        self._target = np.array(psi, dtype=np.float64)
        if self._tau <= 0.0:
            self._p = self._target.copy()

    def pressures(self) -> FloatArray:
        """Current pressures."""
        return self._p.copy()

    def advance(self, dt: float) -> None:
        """Let ``dt`` seconds pass (first-order lag towards the target)."""
        if self._tau > 0.0:
            self._p += (self._target - self._p) * (1.0 - np.exp(-dt / self._tau))


class SimulatedPressureBank:
    """A :class:`~softarm.hardware.protocols.PressureBank` driving a :class:`PressurePlant`.

    Args:
        plant: the simulated arm (or :class:`IdealPlant`).
        channels: number of channels.
        max_pressure: the simulated regulators' full scale (psi).
    """

    def __init__(
        self,
        plant: PressurePlant,
        channels: int = 9,
        max_pressure: float = ITV1031_FULL_SCALE_PSI,
    ) -> None:
        self.plant = plant
        self.faults = Faults()
        self.writes: list[FloatArray] = []  # every command forwarded, for tests and logs
        self._n = channels
        self._max = max_pressure
        self.closed = False

    @property
    def channels(self) -> int:
        """Number of channels."""
        return self._n

    @property
    def max_pressure(self) -> float:
        """Full-scale pressure (psi)."""
        return self._max

    def set_pressures(self, psi: FloatArray) -> None:
        """Forward ``psi`` to the plant.

        Raises:
            HardwareError: the bank is closed (as a real one would: its task is gone).
        """
        self._refuse_if_closed()
        self.faults.check("simulated pressure bank")
        p = np.array(psi, dtype=np.float64)
        if p.shape != (self._n,):
            raise ShapeError(f"psi must have shape ({self._n},), got {p.shape}")
        self.writes.append(p.copy())
        self.plant.command_pressures(p)

    def vent(self) -> None:
        """Command 0 psi everywhere."""
        self.set_pressures(np.zeros(self._n))

    def read_pressures(self) -> FloatArray:
        """The plant's pressures (NaN when the ``nan`` fault is set)."""
        self._refuse_if_closed()
        self.faults.check("simulated pressure bank")
        if self.faults.nan:
            return np.full(self._n, np.nan)
        return np.asarray(self.plant.pressures(), dtype=np.float64)

    def close(self) -> None:
        """Vent if still connected, then refuse every further call (like a closed DAQ
        task), so tests see any use after close. Calling it twice is harmless."""
        if not self.closed and not self.faults.disconnected:
            self.plant.command_pressures(np.zeros(self._n))
        self.closed = True

    def _refuse_if_closed(self) -> None:
        if self.closed:
            raise HardwareError("simulated pressure bank is closed")


class SimulatedGripper:
    """A gripper that moves instantly; ``position`` is the closure fraction."""

    def __init__(self) -> None:
        self.faults = Faults()
        self._position = 0.0

    @property
    def position(self) -> float:
        """0.0 open, 1.0 closed (NaN under the ``nan`` fault)."""
        self.faults.check("simulated gripper")
        return float("nan") if self.faults.nan else self._position

    def open(self) -> None:
        """Open fully."""
        self.faults.check("simulated gripper")
        self._position = 0.0

    def close(self) -> None:
        """Close fully."""
        self.faults.check("simulated gripper")
        self._position = 1.0


class SimulatedRipenessSensor:
    """A ripeness sensor reading ``source()`` (e.g. the ripeness of the berry between
    the simulated fingers) or a constant."""

    def __init__(self, source: Callable[[], float] | float = 1.0) -> None:
        self.faults = Faults()
        self._source = source

    def read(self) -> float:
        """The ripeness index (NaN under the ``nan`` fault)."""
        self.faults.check("simulated ripeness sensor")
        if self.faults.nan:
            return float("nan")
        return float(self._source() if callable(self._source) else self._source)


@dataclass
class SimulatedCamera:
    """A camera whose frames come from ``render()``; ``None`` means a dropped frame."""

    render: Callable[[], Image | None]
    faults: Faults = field(default_factory=Faults)
    closed: bool = False

    def read(self) -> Image | None:
        """One frame or ``None``."""
        if self.closed:
            raise HardwareError("simulated camera is closed")
        self.faults.check("simulated camera")
        return self.render()

    def close(self) -> None:
        """Mark closed."""
        self.closed = True
