"""What every closed-loop stage of the harvest shares: the clock, the controller, the
actuator, the tuning and the log, and the one way a command reaches the arm
(:meth:`ArmLink.send`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.harvest.machine.interfaces import (
    Clock,
    Controller,
    FloatArray,
    Observation,
    PressureActuator,
)
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.states import FaultReason
from softarm.harvest.records.log import HarvestLog
from softarm.harvest_config import HarvestConfig

__all__ = ["SEND_ROUNDING", "ArmLink"]

#: The most (m) the q the safety layer returns differs from the q commanded by rounding
#: alone (m -> psi -> m, about 1e-18): far below what any regulator resolves, far below
#: what a clamp or a rate limit takes off.
SEND_ROUNDING = 1e-12


@dataclass
class ArmLink:
    """The devices and settings the stages share; the controller may be swapped (the
    tests do) and every stage sees the new one."""

    clock: Clock
    controller: Controller
    actuator: PressureActuator
    cfg: HarvestConfig
    log: HarvestLog

    def send(self, q: FloatArray) -> FloatArray:
        """Command ``q``; returns the q to go on from: what the safety layer let through,
        or ``q`` itself where that differs from it only by the rounding of the m -> psi
        -> m round trip (``SEND_ROUNDING``): holding a q it let through must not drift it.
        Every stage goes on from what was sent: the safety layer may have clamped or
        rate-limited it."""
        sent = self.actuator.send(q)
        rounding = float(np.max(np.abs(sent - q), initial=0.0)) <= SEND_ROUNDING
        return np.asarray(q, dtype=np.float64) if rounding else sent

    def hold(self, q: FloatArray) -> FloatArray:
        """Keep commanding ``q`` (it also feeds the safety layer's watchdog) and wait;
        returns the q sent, the one to go on from."""
        q = self.send(q)
        self.clock.sleep(self.cfg.period)
        return q

    def arrived(self) -> bool:
        """Whether the lag model (if any) has every actuator within ``arrival_tolerance``
        of the q last sent."""
        left = self.actuator.in_flight()
        return left is None or float(np.max(np.abs(left))) <= self.cfg.arrival_tolerance

    def look(self, watch: BerryWatch, q: FloatArray, need_fix: bool) -> Observation:
        """``watch.observe``; a marker lost while the arm is out in the bush at ``q``
        carries ``q`` as the place to back out from (open loop if the cube is gone)."""
        try:
            return watch.observe(need_fix=need_fix)
        except Fault as fault:
            if fault.reason is FaultReason.MARKER_LOST and fault.retreat_from is None:
                fault.retreat_from = q
            raise
