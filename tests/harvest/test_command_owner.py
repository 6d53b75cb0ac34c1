"""One owner of the command: the machine's q is what the safety layer last let through
(the actuator's ``sent``), never a second copy, and a held command goes on from what
was sent."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.harvest import BerryTarget, HarvestConfig, HarvestLog
from softarm.harvest.servo import Servo

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
    held = servo._hold(np.array([0.005, 0.02, 0.01]))
    np.testing.assert_array_equal(held, [0.005, 0.01, 0.01])
