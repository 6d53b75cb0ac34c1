"""ResolverController: the closed loop with the lag model, and plan following with the
transport resolver (docs/control.md, section 6)."""

import numpy as np

import softarm
from softarm import Gains, Resolver
from softarm.harvest.control.controller import ResolverController


def _setup() -> tuple[softarm.SoftArm, np.ndarray, np.ndarray, np.ndarray]:
    arm = softarm.SoftArm.blackberry()
    q = np.full(arm.n_actuators, 0.0167)
    target = np.asarray(arm.forward(q + 0.002 * np.arange(arm.n_actuators) / 9))
    measured = np.asarray(arm.forward(q))
    return arm, q, target, measured


def test_follow_step_uses_the_transport_resolver() -> None:
    arm, q, target, measured = _setup()
    fast = Resolver(arm, mode="hybrid", gains=Gains())
    bound = Resolver(arm, mode="hybrid", gains=Gains.for_lag(1.0, 0.05))
    in_flight = q - 0.003  # the lag model: 3 mm still to come on every channel
    ctl = ResolverController(fast, (), lambda: in_flight, transport=bound)
    follow, _ = ctl.follow_step(q, target, measured)
    expected = bound.step(q, target, measured).q
    np.testing.assert_array_equal(follow, expected)
    # The closed loop on the berry keeps the lag model and the mode's gain.
    servo, _ = ctl.step(q, target, measured)
    np.testing.assert_array_equal(servo, fast.step(q, target, measured, plant_q=in_flight).q)
    # The bound gain moves less per step than the predictor's.
    assert np.linalg.norm(follow - q) < np.linalg.norm(servo - q)


def test_without_transport_follow_step_is_step() -> None:
    arm, q, target, measured = _setup()
    ctl = ResolverController(Resolver(arm, mode="hybrid"), ())
    np.testing.assert_array_equal(
        ctl.follow_step(q, target, measured)[0], ctl.step(q, target, measured)[0]
    )
