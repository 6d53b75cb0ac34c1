"""NI-DAQmx analog-output pressure bank: psi → 0–5 V → proportional regulators.

The paper drives nine SMC ITV1031 regulators from a PCI-6703 analog output board
(section II-D). Here one NI-DAQmx task holds the nine voltage channels in actuator order
and every command is written to all of them at once. The pressure → voltage map is
:class:`~softarm.hardware.pressure_map.VoltageMap` (its docstring states the assumed
regulator range).

``nidaqmx`` is an optional extra (``pip install softarm[hardware]``), imported only
when a bank is opened, so the rest of softarm works without it.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.errors import HardwareError, HardwareUnavailableError, ShapeError
from softarm.hardware.pressure_map import VoltageMap

__all__ = ["NidaqPressureBank", "import_nidaqmx"]


def import_nidaqmx() -> ModuleType:
    """Import ``nidaqmx`` or raise :class:`HardwareUnavailableError` saying how to get it."""
    try:
        return importlib.import_module("nidaqmx")
    except ImportError as exc:
        raise HardwareUnavailableError(
            "the NI-DAQmx pressure bank needs the Python package 'nidaqmx', which is not "
            "installed: pip install 'softarm[hardware]' (and NI-DAQmx from ni.com)"
        ) from exc


class NidaqPressureBank:
    """A :class:`~softarm.hardware.protocols.PressureBank` on NI-DAQmx voltage outputs.

    Args:
        channels: physical channel names in actuator order, e.g. ``"Dev1/ao0"``.
        voltage_map: the regulators' pressure ↔ voltage map.
        monitor: optional pressure measurement (psi) for :meth:`read_pressures`, e.g.
            the Arduino pressure board; without it the last command is returned.

    Raises:
        HardwareUnavailableError: ``nidaqmx`` is missing or the device cannot be opened.
    """

    def __init__(
        self,
        channels: Sequence[str],
        voltage_map: VoltageMap | None = None,
        monitor: Callable[[], FloatArray] | None = None,
    ) -> None:
        if len(channels) == 0:
            raise ShapeError("channels must name at least one analog output, got []")
        self._names = list(channels)
        self._map = voltage_map if voltage_map is not None else VoltageMap()
        self._monitor = monitor
        self._last = np.zeros(len(self._names))
        nidaqmx = import_nidaqmx()
        self._task: Any = None
        try:
            task = nidaqmx.Task()
            self._task = task
            for name in self._names:
                task.ao_channels.add_ao_voltage_chan(
                    name, min_val=self._map.v_min, max_val=self._map.v_max
                )
        except Exception as exc:
            # nidaqmx raises DaqError/DaqNotFoundError when NI-DAQmx or the board is absent.
            self._release()
            raise HardwareUnavailableError(
                f"cannot open NI-DAQmx analog outputs {self._names}: {exc}"
            ) from exc
        self.vent()

    @property
    def channels(self) -> int:
        """Number of analog output channels."""
        return len(self._names)

    @property
    def max_pressure(self) -> float:
        """The regulators' full-scale pressure (psi)."""
        return self._map.full_scale_psi

    def set_pressures(self, psi: FloatArray) -> None:
        """Write the voltages for ``psi`` (clamped to the regulator range) to every channel."""
        p = np.asarray(psi, dtype=np.float64)
        if p.shape != (self.channels,):
            raise ShapeError(f"psi must have shape ({self.channels},), got {p.shape}")
        volts = self._map.to_volts(p)  # raises NonFiniteError, clamps into [v_min, v_max]
        if self._task is None:
            raise HardwareError(f"NI-DAQmx task for {self._names} is closed")
        try:
            self._task.write([float(v) for v in volts], auto_start=True)
        except Exception as exc:
            raise HardwareError(f"NI-DAQmx write to {self._names} failed: {exc}") from exc
        self._last = self._map.to_psi(volts)

    def vent(self) -> None:
        """Write 0 psi (``v_min``) to every channel."""
        self.set_pressures(np.zeros(self.channels))

    def read_pressures(self) -> FloatArray:
        """Measured pressures if a monitor was given, else the last command (psi).

        Raises:
            HardwareError: the monitor's reading is not ``channels`` finite numbers.
        """
        if self._monitor is None:
            return self._last.copy()
        try:
            p = np.asarray(self._monitor(), dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise HardwareError(f"pressure monitor returned a non-numeric reading: {exc}") from exc
        if p.shape != (self.channels,) or not np.all(np.isfinite(p)):
            raise HardwareError(
                f"pressure monitor must return {self.channels} finite values (psi), got {p!r}"
            )
        return p

    def close(self) -> None:
        """Vent, then close the task. Calling it twice is harmless."""
        if self._task is None:
            return
        try:
            self.vent()
        finally:
            self._release()

    def _release(self) -> None:
        task, self._task = self._task, None
        if task is not None:
            task.close()
