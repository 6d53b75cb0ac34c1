"""Every stage of the state machine is bounded in time (issue 26, item 2). The IDLE ramp
to the ready pose ran with ``deadline=inf``: with a lag model that never has the arm
there (a model file with an offset of 1e300), `harvest --sim` stayed in IDLE for 6,358
simulated seconds, logging 2,000 lines a second."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.harvest import BerryTarget, FaultReason, HarvestState

from .fakes import make_rig

#: Far past every stage's budget: reaching it means a stage runs unbounded.
RUNAWAY_S = 600.0


def _stop_runaway(t: float) -> None:
    if t > RUNAWAY_S:
        raise AssertionError(f"still running at {t:.0f} s of simulated time")


def test_an_arm_that_never_settles_times_out_in_idle() -> None:
    rig = make_rig()
    rig.clock.hooks.append(_stop_runaway)
    rig.machine.actuator.in_flight = lambda: np.ones(3)  # type: ignore[method-assign]
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.TIMEOUT
    assert rig.transitions(1) == [HarvestState.IDLE, HarvestState.FAULT]
    assert rig.clock.t <= rig.machine.config.idle_timeout + 1.0
    assert rig.vented()


def test_a_ramp_refuses_an_unbounded_deadline() -> None:
    rig = make_rig()
    m = rig.machine
    from softarm.harvest.machine.observe import BerryWatch

    watch = BerryWatch(m.vision, m.clock, BerryTarget(1), m.log, 1.0)
    with pytest.raises(ParameterError, match="deadline"):
        m.servo.transport.ramp(watch, HarvestState.IDLE, m.q, m.home, float("inf"))
