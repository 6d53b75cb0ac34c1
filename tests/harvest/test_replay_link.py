"""The dry run's Arduino (:class:`ReplayLink`) gives the recorded ripeness readings; one
asked for beyond them ends the berry in FAULT with that reason stated, vented, and stops
the run: no crash."""

from __future__ import annotations

import pytest

from softarm.errors import HardwareError
from softarm.hardware.arduino_devices import ArduinoRipenessSensor
from softarm.harvest import BerryTarget, FaultReason, HarvestState
from softarm.harvest.rigs.replay.devices import RecordingExhaustedError, ReplayLink
from softarm.harvest.runs.policy import run_targets

from .fakes import make_rig


def test_the_readings_in_order_then_a_stated_device_error() -> None:
    link = ReplayLink([0.9, 0.2], "rec")
    assert [link.request("NIR"), link.request("NIR")] == [["0.9"], ["0.2"]]
    with pytest.raises(RecordingExhaustedError, match="rec: no ripeness reading left"):
        link.request("NIR")
    with pytest.raises(HardwareError, match="no reply to 'PING'"):
        link.request("PING")


def test_a_replay_out_of_readings_ends_the_berry_with_its_reason() -> None:
    rig = make_rig()
    rig.machine.ripeness = ArduinoRipenessSensor(ReplayLink([0.9], "rec"))
    report = run_targets(
        rig.machine.run_berry, [BerryTarget(1), BerryTarget(2), BerryTarget(1)], rig.machine.log
    )
    first, second, third = report.berries
    assert first.harvested  # the one recorded reading
    assert second.fault is FaultReason.HARDWARE_ERROR and not second.harvested
    assert report.stopped is FaultReason.HARDWARE_ERROR  # nothing further to replay
    assert third.final_state is HarvestState.IDLE
    records = rig.machine.log.records
    (fault,) = [r for r in records if r["kind"] == "fault"]
    assert "no ripeness reading left to replay" in fault["detail"]
    assert not [r for r in records if r["kind"] == "crash"]
    assert rig.vented()
