"""The pressure actuator of the harvest loop: elongations (m) → psi → safety layer.

It owns what the arm was actually sent: the safety layer clamps and rate-limits every
command, so the q a controller asked for is not always the q the regulators got.
:attr:`SafeActuator.sent` is the latter (the state the resolver linearises at), and with
a known lag :attr:`SafeActuator.plant_q` is the resolver's ``plant_q``: the q sent less
the motion still in flight by a :class:`~softarm.harvest.control.plant_model.MeasurementModel`
fed with every command sent (ramps and holds included), for the lag-aware closed loop
(docs/control.md, section 6).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np
import numpy.typing as npt

from softarm._core import lead_gain
from softarm.checks import FloatArray
from softarm.errors import NonFiniteError, ParameterError
from softarm.hardware.pressure_map import ElongationMap
from softarm.hardware.safety import SafePressureBank
from softarm.harvest.control.plant_model import MeasurementModel

__all__ = ["SafeActuator", "lead_gain"]


class PressureMap(Protocol):
    """Elongation (m) <-> psi, per actuator: an :class:`ElongationMap` or a calibration's
    :class:`~softarm.calibration.result.GainMap`."""

    def to_psi(self, elongation: npt.ArrayLike, *, clamp: bool = True) -> FloatArray: ...

    def to_elongation(self, psi: npt.ArrayLike, *, clamp: bool = True) -> FloatArray: ...


class SafeActuator:
    """Sends elongations through ``bank`` (a :class:`SafePressureBank`, which clamps,
    rate-limits and watches every command) using ``pressure_map`` (the paper's 1/2100 m
    per psi, section IV-A). Implements
    :class:`~softarm.harvest.machine.interfaces.PressureActuator`.

    Args:
        bank: the safety layer.
        pressure_map: elongation ↔ psi (``to_psi``/``to_elongation``).
        lag: ``(tau_s, period_s)`` of the regulators: :attr:`plant_q` follows the sent
            commands through that lag. None: no prediction.
        sensor_lag_s: the time constant (s) of the pose measurement's own first-order
            filter, after the actuators (0: no filter).
        play_m: the play band width (m of elongation; one, or one per channel) the lag
            model puts between the regulators and the measurement (0: none; needs
            ``lag``).
        lead: pre-compensation of the regulators' lag, ``k``: they are told
            ``q + k (q − ŷ)`` with ``ŷ`` the lag model's pressure, so that a first-order
            regulator approaches ``q`` ``1 + k`` times faster (``k ≤ a/(1 − a)``,
            ``a = e^{−T/τ}``, keeps it free of overshoot). 0: none.
        now: the clock (s) the commands are stamped with, for the prediction to count
            the periods between two commands (a grasp sends nothing for a while).
    """

    def __init__(
        self,
        bank: SafePressureBank,
        pressure_map: PressureMap | None = None,
        *,
        lag: tuple[float, float] | None = None,
        now: Callable[[], float] | None = None,
        sensor_lag_s: float = 0.0,
        lead: float = 0.0,
        play_m: float | FloatArray = 0.0,
    ) -> None:
        self.bank = bank
        self.pressure_map: PressureMap = pressure_map or ElongationMap(max_psi=bank.max_pressure)
        n = bank.channels
        if lag is not None and now is None:
            raise ParameterError("lag: needs the clock `now` to count periods")
        self._now = now
        self._sent = np.zeros(n)
        self._model = (
            None if lag is None else MeasurementModel(n, lag[0], lag[1], sensor_lag_s, play_m)
        )
        self._stamp = None if now is None else now()
        # What the regulators were told, boost included (the lag model's input).
        self._drive = np.zeros(n)
        if not (np.isfinite(lead) and 0.0 <= lead <= 20.0):
            raise ParameterError(f"lead = {lead!r}: must be in [0, 20]")
        if lead > 0 and lag is None:
            raise ParameterError("lead: needs the lag model (`lag`)")
        if np.any(np.asarray(play_m) != 0) and lag is None:
            raise ParameterError("play_m: needs the lag model (`lag`)")
        self._lead = float(lead)

    @property
    def sent(self) -> FloatArray:
        """The elongations (m) the regulators were last sent towards, after the safety
        layer's clamp and rate limit (a copy)."""
        return self._sent.copy()

    @property
    def plant_q(self) -> FloatArray | None:
        """The resolver's ``plant_q`` (m): :attr:`sent` less the motion the measured pose
        will still make towards it, i.e. ŷ (docs/control.md §6); None
        without a lag model."""
        if self._model is None:
            return None
        self._catch_up()
        return self._sent - self._model.in_flight()

    def in_flight(self) -> FloatArray | None:
        """The motion (m) the actuators will still make towards :attr:`sent`, by the lag
        model of the regulators (the measurement's own lag left out: this is where the
        arm is, not what the cameras show yet); None without a lag model."""
        if self._model is None:
            return None
        self._catch_up()
        return self._model.arm_in_flight()

    def play_band(self) -> tuple[FloatArray, FloatArray] | None:
        """The lag model's play output now and its band widths (m; None without a lag
        model): a channel commanded within half a width of its output does not move."""
        if self._model is None:
            return None
        self._catch_up()
        return self._model.play_band()

    def send(self, q: FloatArray) -> FloatArray:
        """Command elongations ``q`` (m); returns :attr:`sent`. A NaN raises before
        anything is sent."""
        q = np.asarray(q, dtype=np.float64)
        if not np.all(np.isfinite(q)):
            raise NonFiniteError(f"q must be finite, got {q.tolist()!r}")
        self._catch_up()
        wanted = self.pressure_map.to_psi(q)
        boost = np.zeros_like(wanted)
        if self._lead > 0 and self._model is not None:
            boost = self._boost(
                wanted, self._lead * (wanted - self.pressure_map.to_psi(self._model.regulators))
            )
        self.bank.set_pressures(np.clip(wanted + boost, 0.0, self.bank.max_pressure))
        drive = self.bank.last_sent
        self._drive = self.pressure_map.to_elongation(drive)
        # The target the regulators are driven towards: the wanted pressure while the
        # boost pushes past it, what the safety layer let through when it held the
        # command short of it.
        target = np.where(
            boost > 0,
            np.minimum(wanted, drive),
            np.where(boost < 0, np.maximum(wanted, drive), drive),
        )
        self._sent = self.pressure_map.to_elongation(target)
        if self._model is not None:
            self._model.command(self._sent)
        return self.sent

    def _boost(self, wanted: FloatArray, boost: FloatArray) -> FloatArray:
        """``boost`` scaled as one vector, never clipped channel by channel, so that the
        command stays in ``[0, p_max]`` and within one period of the safety layer's rate
        limit: the regulators then head along the same direction in q as without it, and
        the arm stays on the straight line between plan waypoints (docs/control.md §6)."""
        last = self.bank.last_sent
        step = self.bank.max_rate * (self._model.period if self._model is not None else 0.0)
        lo = np.maximum(0.0, last - step) - wanted  # s * boost must stay in [lo, hi]
        hi = np.minimum(self.bank.max_pressure, last + step) - wanted
        with np.errstate(divide="ignore", invalid="ignore"):
            limit = np.where(boost > 0, hi / boost, np.where(boost < 0, lo / boost, np.inf))
        scale = float(np.clip(np.min(limit, initial=1.0), 0.0, 1.0))
        return scale * boost

    def vent(self, reason: str) -> None:
        """Vent every channel; the safety layer logs ``reason``."""
        self._catch_up()
        self.bank.vent(reason)
        self._sent = np.zeros_like(self._sent)
        self._drive = np.zeros_like(self._drive)
        if self._model is not None:
            self._model.command(self._sent)

    def _catch_up(self) -> None:
        """Advance the lag model over the whole periods since the last command, with the
        command held (the regulators held it)."""
        if self._model is None or self._now is None or self._stamp is None:
            return
        periods = int(np.floor((self._now() - self._stamp) / self._model.period + 1e-9))
        for _ in range(min(periods, 10_000)):
            self._model.advance(self._drive)
        self._stamp += periods * self._model.period
