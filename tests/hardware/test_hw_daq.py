"""NidaqPressureBank against a fake ``nidaqmx`` module injected into the lazy import."""

from __future__ import annotations

import sys
import types

import numpy as np
import pytest

from softarm.errors import HardwareError, HardwareUnavailableError, NonFiniteError, ShapeError
from softarm.hardware.daq import NidaqPressureBank
from softarm.hardware.pressure_map import VoltageMap
from softarm.hardware.safety import SafePressureBank

CHANNELS = [f"Dev1/ao{i}" for i in range(9)]


class FakeTask:
    def __init__(self, module: types.SimpleNamespace) -> None:
        self.module = module
        self.channels: list[tuple[str, float, float]] = []
        self.writes: list[list[float]] = []
        self.closed = False
        self.ao_channels = types.SimpleNamespace(add_ao_voltage_chan=self._add)
        module.tasks.append(self)

    def _add(self, name: str, min_val: float, max_val: float) -> None:
        if self.module.missing_device:
            raise RuntimeError(f"Device identifier is invalid: {name}")
        self.channels.append((name, min_val, max_val))

    def write(self, data: list[float], auto_start: bool) -> None:
        assert auto_start
        self.writes.append(list(data))

    def close(self) -> None:
        self.closed = True


@pytest.fixture
def fake_nidaqmx(monkeypatch: pytest.MonkeyPatch) -> types.SimpleNamespace:
    module = types.SimpleNamespace(tasks=[], missing_device=False)
    module.Task = lambda: FakeTask(module)
    monkeypatch.setitem(sys.modules, "nidaqmx", module)
    return module


def test_missing_package_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "nidaqmx", None)  # makes `import nidaqmx` fail
    with pytest.raises(HardwareUnavailableError, match=r"nidaqmx.*softarm\[hardware\]"):
        NidaqPressureBank(CHANNELS)


def test_missing_device_is_unavailable_and_releases_the_task(fake_nidaqmx) -> None:
    fake_nidaqmx.missing_device = True
    with pytest.raises(HardwareUnavailableError, match="Dev1/ao0"):
        NidaqPressureBank(CHANNELS)
    assert fake_nidaqmx.tasks[0].closed


def test_voltages_follow_the_map_and_stay_in_range(fake_nidaqmx) -> None:
    vmap = VoltageMap()
    bank = NidaqPressureBank(CHANNELS, vmap)
    task = fake_nidaqmx.tasks[0]
    assert [c[0] for c in task.channels] == CHANNELS
    assert all((lo, hi) == (0.0, 5.0) for _, lo, hi in task.channels)
    assert task.writes == [[0.0] * 9]  # vented on open
    psi = np.array([0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 72.0])
    bank.set_pressures(psi)
    np.testing.assert_allclose(task.writes[-1], psi * 5.0 / vmap.full_scale_psi)
    bank.set_pressures(np.array([-10.0, 1e4, 0, 0, 0, 0, 0, 0, 0]))  # clamped, not sent raw
    assert task.writes[-1][:2] == [0.0, 5.0]
    np.testing.assert_allclose(bank.read_pressures()[:2], [0.0, vmap.full_scale_psi])
    for w in task.writes:
        assert all(0.0 <= v <= 5.0 for v in w)
    bank.close()
    assert task.writes[-1] == [0.0] * 9 and task.closed
    with pytest.raises(HardwareError, match="closed"):
        bank.set_pressures(np.zeros(9))


def test_rejects_bad_commands_without_writing(fake_nidaqmx) -> None:
    bank = NidaqPressureBank(CHANNELS)
    task = fake_nidaqmx.tasks[0]
    with pytest.raises(NonFiniteError):
        bank.set_pressures(np.r_[np.nan, np.zeros(8)])
    with pytest.raises(ShapeError, match=r"\(9,\)"):
        bank.set_pressures(np.zeros(3))
    assert len(task.writes) == 1


def test_behind_the_safety_layer(fake_nidaqmx) -> None:
    t = [0.0]
    bank = NidaqPressureBank(CHANNELS)
    with SafePressureBank(bank, 70.0, 50.0, 1.0, clock=lambda: t[0], watchdog_thread=False) as s:
        s.set_pressures(np.zeros(9))
        for _ in range(30):
            t[0] += 0.1
            s.set_pressures(np.full(9, 100.0))
    writes = np.array(fake_nidaqmx.tasks[0].writes)
    assert writes.max() == pytest.approx(5.0 * 70.0 / VoltageMap().full_scale_psi)
    assert writes.min() == 0.0 and not writes[-1].any()


@pytest.mark.parametrize("reading", [np.zeros(8), np.r_[np.zeros(8), np.nan], ["x"] * 9])
def test_a_bad_monitor_reading_is_a_hardware_error(fake_nidaqmx, reading: object) -> None:
    bank = NidaqPressureBank(CHANNELS, monitor=lambda: reading)  # type: ignore[arg-type,return-value]
    with pytest.raises(HardwareError, match="pressure monitor"):
        bank.read_pressures()
    bank.close()
