"""One owner per state: the machine alone writes the berry's result, the stages keep no
state of a berry, and one BerryWatch decides when a marker is lost."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.harvest import BerryTarget, FaultReason, HarvestLog, Observation
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.states import HarvestState
from softarm.harvest.runs.policy import run_targets

from .fakes import FakeClock, make_rig


def test_the_stages_keep_no_state_of_a_berry() -> None:
    rig = make_rig()
    run_targets(rig.machine.run_berry, [BerryTarget(1), BerryTarget(3)], rig.machine.log)
    servo = rig.machine.servo
    assert set(vars(servo)) == {"link", "transport", "berry_loop"}
    assert set(vars(servo.link)) == {"clock", "controller", "actuator", "cfg", "log"}
    assert vars(servo.transport) == vars(servo.berry_loop) == {"link": servo.link}


@pytest.mark.parametrize("tag", [1, 3])  # harvested, and unreachable (a fault mid-stage)
def test_the_result_counts_every_step_logged_also_up_to_a_fault(tag: int) -> None:
    rig = make_rig()
    result = rig.machine.run_berry(BerryTarget(tag))
    steps = [r for r in rig.machine.log.records if r["kind"] == "step" and r["berry"] == tag]
    assert result.steps == len(steps) > 0
    assert (result.fault is FaultReason.UNREACHABLE) == (tag == 3)
    assert np.isfinite(result.position_error_mm)  # the last step's, also when it faulted
    assert result.target is not None


class _Blank:
    """A vision that never sees anything."""

    def select(self, berry: BerryTarget) -> None:
        pass

    def observe(self, time: float, need_fix: bool = True) -> Observation:
        return Observation(time, None, None)


def test_marker_loss_counts_from_the_last_restart() -> None:
    clock = FakeClock()
    watch = BerryWatch(_Blank(), clock, BerryTarget(1), HarvestLog(), marker_timeout=0.5)
    clock.sleep(0.4)
    watch.observe()  # 0.4 s unseen: within the timeout
    clock.sleep(0.2)
    watch.restart()  # a stage that starts now forgives the time before
    clock.sleep(0.4)
    assert watch.observe().pose is None
    clock.sleep(0.2)
    with pytest.raises(Fault, match=r"cube not seen for 0\.60 s") as info:
        watch.observe()
    assert info.value.reason is FaultReason.MARKER_LOST


class _CubeOnly(_Blank):
    """Sees the cube, never the berry."""

    def observe(self, time: float, need_fix: bool = True) -> Observation:
        return Observation(time, np.eye(4), None)


def test_a_stage_that_needs_no_berry_is_not_faulted_for_it() -> None:
    clock = FakeClock()
    watch = BerryWatch(_CubeOnly(), clock, BerryTarget(1), HarvestLog(), marker_timeout=0.5)
    clock.sleep(0.4)
    watch.excuse_berry(clock.now())  # a closed-loop stage starting after an open-loop one
    clock.sleep(0.4)
    watch.observe()  # 0.8 s without the berry, 0.4 s since the stage began
    clock.sleep(1.0)
    assert watch.observe(need_fix=False).fix is None  # the way home: no berry needed
    with pytest.raises(Fault, match=r"berry not seen for 1\.40 s"):
        watch.observe()
    watch.log_step(HarvestState.IDLE, watch.blind(), np.zeros(3), None, None, False)
    assert watch.steps == 1
