"""Every stage of the state machine is bounded in time (issue 26, item 2). The IDLE ramp
to the ready pose once ran with ``deadline=inf``: with a lag model that never has the arm
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


def test_an_arm_that_never_settles_ends_the_berry_within_its_stages_deadlines() -> None:
    # IDLE hands over once its command is at the ready pose; placement, which waits for
    # the lag model's arm, then times out and the way home's ramp after it too.
    rig = make_rig()
    rig.clock.hooks.append(_stop_runaway)
    rig.machine.actuator.in_flight = lambda: np.ones(3)  # type: ignore[method-assign]
    result = rig.machine.run_berry(BerryTarget(1))
    c = rig.machine.config
    assert result.fault is FaultReason.TIMEOUT
    assert rig.transitions(1)[-1] is HarvestState.FAULT
    assert rig.clock.t <= c.idle_timeout + c.placement_timeout + c.home_timeout + 1.0
    assert rig.vented()


def test_a_settling_ramp_whose_arm_never_arrives_times_out_at_its_deadline() -> None:
    from softarm.harvest.machine.observe import BerryWatch
    from softarm.harvest.machine.outcome import Fault

    rig = make_rig()
    m = rig.machine
    m.actuator.in_flight = lambda: np.ones(3)  # type: ignore[method-assign]
    watch = BerryWatch(m.vision, m.clock, BerryTarget(1), m.log, 1.0)
    with pytest.raises(Fault, match="not settled in time") as err:
        m.servo.transport.ramp(watch, HarvestState.RETURN_HOME, m.q, m.home, 2.0)
    assert err.value.reason is FaultReason.TIMEOUT
    assert 2.0 < rig.clock.t <= 2.0 + 2 * m.config.period


def test_a_ramp_refuses_an_unbounded_deadline() -> None:
    rig = make_rig()
    m = rig.machine
    from softarm.harvest.machine.observe import BerryWatch

    watch = BerryWatch(m.vision, m.clock, BerryTarget(1), m.log, 1.0)
    with pytest.raises(ParameterError, match="deadline"):
        m.servo.transport.ramp(watch, HarvestState.IDLE, m.q, m.home, float("inf"))
