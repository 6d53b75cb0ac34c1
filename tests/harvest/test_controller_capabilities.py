"""The servo's controller declares everything the loop uses (plan following, the model's
pose and limits, the way check): one that lacks any of it is refused when the machine is
built, not found out mid-harvest by a plan that is silently not followed."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import CapabilityError
from softarm.harvest import HarvestMachine, SafeActuator
from softarm.harvest.machine.interfaces import CONTROLLER_METHODS, require_controller

from .fakes import FakeClock, FakeController, make_rig


class _StepOnly:
    def step(self, q, target, current):
        return np.asarray(q), False


def test_a_controller_with_only_step_is_refused_naming_what_it_lacks() -> None:
    rig = make_rig()
    with pytest.raises(CapabilityError, match="_StepOnly lacks follow_step, model_pose"):
        HarvestMachine(
            FakeClock(), rig.machine.vision, _StepOnly(), SafeActuator(rig.bank),
            rig.gripper, rig.ripeness, n_actuators=3,
        )  # fmt: skip


def test_the_fake_controller_declares_every_capability() -> None:
    fake = FakeController()
    assert require_controller(fake) is fake
    assert all(callable(getattr(fake, m)) for m in CONTROLLER_METHODS)
