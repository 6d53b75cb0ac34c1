"""IDLE's ramp to the ready pose hands over to placement once its command is there, not
once the slow arm is: placement follows from where the lag model has the arm, each
command's way checked from there, so the first berry does not wait for the arm to rise
from vented."""

from __future__ import annotations

from typing import Any

import numpy as np

from softarm.harvest import BerryTarget, HarvestConfig, HarvestLog, HarvestMachine, SafeActuator
from softarm.harvest.machine.states import HarvestState

from .fakes import BERRIES, FakeGripper, FakeLocator, FakeRipeness, FakeTracker, FakeVision
from .test_stage_ahead import PredictingController, slow_actuator


def _machine() -> tuple[HarvestMachine, SafeActuator]:
    clock, plant, actuator = slow_actuator()
    locator = FakeLocator(dict(BERRIES))
    machine = HarvestMachine(
        clock, FakeVision(FakeTracker(plant), locator),  # type: ignore[arg-type]
        PredictingController(actuator), actuator, FakeGripper(), FakeRipeness({}, locator),
        n_actuators=3, config=HarvestConfig(), log=HarvestLog(),
    )  # fmt: skip
    return machine, actuator


def test_placement_begins_while_the_arm_still_rises_to_the_ready_pose() -> None:
    machine, actuator = _machine()
    left_at_placement: list[float] = []
    transition = machine._transition

    def spy(new: HarvestState, berry: BerryTarget, reason: str) -> None:
        if new is HarvestState.INITIAL_PLACEMENT and not left_at_placement:
            flight = actuator.in_flight()
            assert flight is not None
            left_at_placement.append(float(np.max(np.abs(flight))))
        transition(new, berry, reason)

    machine._transition = spy  # type: ignore[method-assign]
    result = machine.run_berry(BerryTarget(1))
    assert result.harvested
    # The command is at the ready pose, the arm (a regulator's lag behind) still mm short.
    assert np.allclose(_first_placement_command(machine), machine.home)
    assert left_at_placement[0] > 3 * machine.config.arrival_tolerance


def _first_placement_command(machine: HarvestMachine) -> Any:
    """The q of the last IDLE step logged: where IDLE left the command."""
    steps = [r for r in machine.log.records if r["kind"] == "step" and r["state"] == "idle"]
    return np.asarray(steps[-1]["q"])
