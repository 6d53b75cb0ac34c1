"""The ready pose between berries on a slow plant that is not the controller's model: the
way home ends once home is commanded, not once the arm is there, and the next berry's
plan is followed from where the lag model has the arm, the way to its first command
checked from there (``Transport.clear_way``)."""

from __future__ import annotations

import numpy as np

from softarm.harvest.machine.states import HarvestState

from .test_stage_ahead import BERRIES, P0, _slow_rig

HOME = np.full(3, 0.0167)
AXIS = np.array([0.0, 1.0, 0.0])


def test_the_way_home_ends_once_home_is_commanded_with_the_arm_still_on_its_way() -> None:
    """Before, the ramp home held its end until every actuator was within
    ``arrival_tolerance`` of home (0.75 s a berry on the slow plant)."""
    clock, _, actuator, servo, watch, _ = _slow_rig()
    config = servo.link.cfg
    q = (BERRIES[1] - (config.standoff + config.grasp_offset) * AXIS - P0) / 3.0
    q = servo.transport.ramp(watch, HarvestState.INITIAL_PLACEMENT, np.zeros(3), q, 30.0)
    q = servo.transport.way_back(watch, HarvestState.RETURN_HOME, q, (HOME,), clock.now())
    np.testing.assert_array_equal(q, HOME)
    left = actuator.in_flight()
    assert left is not None and np.max(np.abs(left)) > config.arrival_tolerance


def test_the_next_plan_is_checked_from_where_the_unsettled_arm_is() -> None:
    """The next berry's placement starts from home commanded, the arm still coming in:
    the way to its first command is checked from the lag model's arm, not from home."""
    _, _, actuator, servo, watch, _ = _slow_rig()
    q = servo.transport.ramp(watch, HarvestState.IDLE, np.zeros(3), HOME, 30.0, settle=False)
    starts: list[np.ndarray] = []

    def way_gaps(q0: np.ndarray, q1: np.ndarray, steps: int = 8) -> np.ndarray:
        starts.append(np.array(q0))
        return np.full(steps, 1.0)  # every way clear

    servo.link.controller.way_gaps = way_gaps  # type: ignore[method-assign]
    flight = actuator.in_flight()
    assert flight is not None and np.max(np.abs(flight)) > servo.link.cfg.arrival_tolerance
    q_pre = (BERRIES[1] - 0.08 * AXIS - P0) / 3.0
    servo.transport.follow(watch, HarvestState.INITIAL_PLACEMENT, q, q_pre, 30.0)
    assert np.max(np.abs(starts[0] - HOME)) > servo.link.cfg.arrival_tolerance
    np.testing.assert_allclose(starts[0], HOME - flight, atol=1e-3)
