"""One owner of the command: the machine's q is what the safety layer last let through
(the actuator's ``sent``), never a second copy, and a held command goes on from what
was sent."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.harvest import BerryTarget, HarvestConfig, HarvestLog
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.stages.servo import Servo
from softarm.harvest.machine.states import FaultReason, HarvestState

from .fakes import FakeClock, FakeController, make_rig


def test_the_machines_q_is_the_q_the_safety_layer_let_through() -> None:
    rig = make_rig()
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested
    np.testing.assert_array_equal(rig.machine.q, rig.machine.actuator.sent)
    with pytest.raises(AttributeError):
        rig.machine.q = np.zeros(3)  # type: ignore[misc]
    rig.machine._vent("test")
    np.testing.assert_array_equal(rig.machine.q, np.zeros(3))


class _Clamping:
    """An actuator whose safety layer lets each channel through up to ``top`` (m)."""

    def __init__(self, top: float) -> None:
        self.top = top

    def send(self, q: np.ndarray) -> np.ndarray:
        return np.minimum(q, self.top)


def test_a_held_command_goes_on_from_what_was_sent() -> None:
    servo = Servo(FakeClock(), FakeController(), _Clamping(0.01), HarvestConfig(), HarvestLog())  # type: ignore[arg-type]
    held = servo.link.hold(np.array([0.005, 0.02, 0.01]))
    np.testing.assert_array_equal(held, [0.005, 0.01, 0.01])


class _RateLimited:
    """A safety layer that lets each channel move at most ``step`` (m) per command."""

    def __init__(self, step: float) -> None:
        self.step, self.last = step, np.zeros(3)
        self.sent: list[np.ndarray] = []

    def send(self, q: np.ndarray) -> np.ndarray:
        self.last = np.clip(q, self.last - self.step, self.last + self.step)
        self.sent.append(self.last.copy())
        return self.last.copy()

    def in_flight(self) -> None:
        return None


class _Blind:
    def blind(self) -> object:
        return None

    def log_step(self, *args: object) -> None:
        pass


def test_a_ramp_goes_on_from_what_the_safety_layer_let_through() -> None:
    # home_speed x period = 2.25 mm a period asked; the safety layer lets 1 mm through.
    limited = _RateLimited(0.001)
    cfg = HarvestConfig()
    servo = Servo(FakeClock(), FakeController(), limited, cfg, HarvestLog())  # type: ignore[arg-type]
    goal = np.array([0.02, 0.01, 0.0])
    end = servo.transport.ramp(_Blind(), None, np.zeros(3), goal, deadline=60.0)  # type: ignore[arg-type]
    np.testing.assert_array_equal(end, goal)
    # The ramp asked from where the arm was let go, never from where it had asked: each
    # command is within one step of the last one sent, and it took 20 periods, not 9.
    sent = np.array(limited.sent)
    assert np.all(np.abs(np.diff(sent, axis=0)) <= 0.001 + 1e-15)
    assert len(sent) == 20


def test_a_ramp_the_safety_layer_holds_short_ends_in_a_timeout() -> None:
    servo = Servo(FakeClock(), FakeController(), _Clamping(0.01), HarvestConfig(), HarvestLog())  # type: ignore[arg-type]
    with pytest.raises(Fault) as info:
        servo.transport.ramp(_Blind(), HarvestState.RETURN_HOME, np.zeros(3), np.full(3, 0.02), 5.0)  # type: ignore[arg-type]
    assert info.value.reason is FaultReason.TIMEOUT
