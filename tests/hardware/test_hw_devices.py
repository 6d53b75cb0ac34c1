"""OpenCV camera against a fake cv2, the simulated backends and their fault injection,
and that every backend satisfies its protocol."""

from __future__ import annotations

import sys
import types

import numpy as np
import pytest

from softarm.errors import HardwareError, HardwareUnavailableError
from softarm.hardware.camera import OpenCVCamera
from softarm.hardware.protocols import Camera, Gripper, PressureBank, RipenessSensor
from softarm.hardware.safety import SafePressureBank
from softarm.hardware.simulated import (
    IdealPlant,
    SimulatedCamera,
    SimulatedGripper,
    SimulatedPressureBank,
    SimulatedRipenessSensor,
)

FRAME = np.zeros((4, 6, 3), np.uint8)


class FakeCapture:
    def __init__(self, source: object, opened: bool, frames: list[object]) -> None:
        self.source, self.opened, self.frames = source, opened, frames
        self.released = False
        self.props: dict[int, float] = {}

    def isOpened(self) -> bool:
        return self.opened

    def set(self, prop: int, value: float) -> bool:
        self.props[prop] = value
        return True

    def read(self) -> tuple[bool, object]:
        frame = self.frames.pop(0)
        return frame is not None, frame

    def release(self) -> None:
        self.released = True


@pytest.fixture
def fake_cv2(monkeypatch: pytest.MonkeyPatch) -> types.SimpleNamespace:
    cv2 = types.SimpleNamespace(
        CAP_PROP_FRAME_WIDTH=3, CAP_PROP_FRAME_HEIGHT=4, opened=True, frames=[], captures=[]
    )

    def capture(source: object) -> FakeCapture:
        cap = FakeCapture(source, cv2.opened, cv2.frames)
        cv2.captures.append(cap)
        return cap

    cv2.VideoCapture = capture
    monkeypatch.setitem(sys.modules, "cv2", cv2)
    return cv2


def test_camera_reads_frames_and_none_on_drop(fake_cv2: types.SimpleNamespace) -> None:
    fake_cv2.frames += [FRAME, None, np.zeros((0,), np.uint8)]
    cam = OpenCVCamera(2, width=640, height=480)
    assert isinstance(cam, Camera)
    assert fake_cv2.captures[0].props == {3: 640, 4: 480}
    assert cam.read() is not None
    assert cam.read() is None  # dropped frame
    assert cam.read() is None  # empty frame
    cam.close()
    cam.close()
    assert fake_cv2.captures[0].released
    with pytest.raises(HardwareError, match="closed"):
        cam.read()


def test_camera_that_cannot_open(fake_cv2: types.SimpleNamespace) -> None:
    fake_cv2.opened = False
    with pytest.raises(HardwareUnavailableError, match="cannot open camera '/dev/video9'"):
        OpenCVCamera("/dev/video9")
    assert fake_cv2.captures[0].released


def test_camera_without_opencv(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "cv2", None)
    with pytest.raises(HardwareUnavailableError, match="opencv-python-headless"):
        OpenCVCamera(0)


def test_simulated_backends_satisfy_the_protocols() -> None:
    assert isinstance(SimulatedPressureBank(IdealPlant()), PressureBank)
    assert isinstance(SimulatedGripper(), Gripper)
    assert isinstance(SimulatedRipenessSensor(), RipenessSensor)
    assert isinstance(SimulatedCamera(lambda: FRAME), Camera)


def test_simulated_pressure_bank_drives_the_plant_through_the_safety_layer() -> None:
    plant = IdealPlant(tau_s=0.1)
    t = [0.0]
    bank = SimulatedPressureBank(plant)
    with SafePressureBank(bank, 70.0, 1000.0, 1.0, clock=lambda: t[0], watchdog_thread=False) as s:
        s.set_pressures(np.zeros(9))
        t[0] += 0.1
        s.set_pressures(np.full(9, 40.0))
        plant.advance(1.0)
        np.testing.assert_allclose(s.read_pressures(), 40.0, rtol=1e-3)
    np.testing.assert_allclose(bank.writes[-1], 0.0)


def test_fault_injection() -> None:
    bank, grip, nir = (
        SimulatedPressureBank(IdealPlant()),
        SimulatedGripper(),
        SimulatedRipenessSensor(0.6),
    )
    cam = SimulatedCamera(lambda: None)
    grip.close()
    assert grip.position == 1.0 and nir.read() == 0.6 and cam.read() is None
    for dev in (bank, grip, nir, cam):
        dev.faults.nan = True
    assert (
        np.isnan(bank.read_pressures()).all() and np.isnan(grip.position) and np.isnan(nir.read())
    )
    grip.faults.disconnected = True
    with pytest.raises(HardwareUnavailableError, match="gripper"):
        grip.open()
    nir.faults.error = HardwareError("NIR LED burnt out")
    with pytest.raises(HardwareError, match="LED"):
        nir.read()
    cam.faults.disconnected = True
    with pytest.raises(HardwareUnavailableError, match="camera"):
        cam.read()
