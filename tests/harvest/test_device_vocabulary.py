"""One device vocabulary: the harvest machine's gripper and ripeness sensor are the
protocols of softarm.hardware.protocols, and the simulated and fake devices satisfy them."""

from __future__ import annotations

from softarm.hardware import protocols
from softarm.harvest.machine import interfaces
from softarm.harvest.rigs.sim.devices import SimGripper

from .fakes import FakeGripper, make_rig


def test_the_old_names_are_the_hardware_protocols() -> None:
    assert interfaces.Gripper is protocols.Gripper
    assert interfaces.RipenessSensor is protocols.RipenessSensor
    assert not hasattr(interfaces, "GripperDevice")  # one name for each device
    assert not hasattr(interfaces, "Camera")  # the camera-name Literal is CameraName


def test_the_harvest_devices_satisfy_the_hardware_protocols() -> None:
    grip = FakeGripper()
    assert isinstance(grip, protocols.Gripper)
    assert grip.position == 0.0
    grip.close()
    assert grip.position == 1.0
    rig = make_rig()
    assert isinstance(rig.machine.ripeness, protocols.RipenessSensor)
    assert all(hasattr(SimGripper, name) for name in ("open", "close", "position", "read"))
