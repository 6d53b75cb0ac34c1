"""Fault injection: each fault ends in the safe state (vented), its reason logged."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import HardwareError, HardwareUnavailableError
from softarm.harvest import BerryTarget, FaultReason, HarvestLog, HarvestState, read_log
from softarm.harvest.runs.policy import run_targets

from .fakes import commanded_before_the_vent, make_rig

S = HarvestState


def _fault_events(rig):
    return [r for r in rig.machine.log.records if r["kind"] == "fault"]


def test_camera_dropout_is_marker_lost_and_the_run_goes_on(tmp_path) -> None:
    rig = make_rig(HarvestLog(tmp_path / "log.jsonl"))
    rig.tracker.blind = lambda t: t >= 1.0  # the eye-to-hand camera stops delivering
    report = run_targets(rig.machine.run_berry, [BerryTarget(1), BerryTarget(2)], rig.machine.log)
    assert [b.fault for b in report.berries] == [FaultReason.MARKER_LOST] * 2
    assert report.stopped is None  # not a system fault: each berry was tried
    assert rig.vented() and "marker_lost" in rig.bank.vent_log[1].reason
    assert [r["kind"] for r in read_log(tmp_path / "log.jsonl")] == [
        r["kind"] for r in rig.machine.log.records
    ]


def test_brief_berry_occlusion_holds_the_last_target_and_harvests() -> None:
    rig = make_rig()
    rig.locator.hidden = lambda t: 1.5 <= t < 2.0  # leaves in front of the berry
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.harvested
    assert result.cameras["held"] > 0


def test_long_berry_occlusion_is_marker_lost() -> None:
    rig = make_rig()
    rig.locator.hidden = lambda t: t >= 0.5
    rig.locator.max_age = 0.2  # the hold runs out before the berry is reached
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.MARKER_LOST
    assert "berry not seen" in _fault_events(rig)[0]["detail"]
    assert rig.vented()


def test_serial_disconnect_of_the_gripper_stops_the_run() -> None:
    rig = make_rig()
    rig.gripper.fail_on_close = HardwareUnavailableError("/dev/ttyACM0: disconnected")
    report = run_targets(rig.machine.run_berry, [BerryTarget(1), BerryTarget(2)], rig.machine.log)
    assert report.berries[0].fault is FaultReason.HARDWARE_ERROR
    assert report.stopped is FaultReason.HARDWARE_ERROR
    assert report.berries[1].final_state is S.IDLE and not report.berries[1].harvested
    assert rig.transitions(1)[-2:] == [S.GRASP, S.FAULT]
    assert rig.vented()


def test_daq_error_vents_and_stops_the_run() -> None:
    rig = make_rig()
    real = rig.backend.set_pressures
    writes = {"n": 0}

    def flaky(psi: np.ndarray) -> None:
        writes["n"] += 1
        if writes["n"] == 20:
            raise HardwareError("DAQmx error -200088: task aborted")
        real(psi)

    rig.backend.set_pressures = flaky  # type: ignore[method-assign]
    report = run_targets(rig.machine.run_berry, [BerryTarget(1)], rig.machine.log)
    assert report.stopped is FaultReason.HARDWARE_ERROR
    assert rig.vented()
    assert "DAQmx" in _fault_events(rig)[0]["detail"]


@pytest.mark.parametrize("where", ["pose", "ripeness"])
def test_nan_measurement_vents_and_stops_the_run(where: str) -> None:
    rig = make_rig()
    if where == "pose":
        rig.tracker.nan_after = 1.0
    else:
        rig.ripeness.values[1] = float("nan")
    report = run_targets(rig.machine.run_berry, [BerryTarget(1), BerryTarget(2)], rig.machine.log)
    assert report.berries[0].fault is FaultReason.NAN_MEASUREMENT
    assert report.stopped is FaultReason.NAN_MEASUREMENT
    assert rig.vented()


def test_emergency_stop_is_a_safety_stop() -> None:
    rig = make_rig()
    rig.clock.hooks.append(
        lambda t: t >= 1.0 and not rig.bank.stopped and rig.bank.emergency_stop()
    )
    report = run_targets(rig.machine.run_berry, [BerryTarget(1)], rig.machine.log)
    assert report.stopped is FaultReason.SAFETY_STOP
    assert rig.vented()


def test_every_fault_transition_is_logged_with_its_reason() -> None:
    rig = make_rig()
    run_targets(rig.machine.run_berry, [BerryTarget(3)], rig.machine.log)
    fault = _fault_events(rig)[0]
    trans = [r for r in rig.machine.log.records if r["kind"] == "transition"][-1]
    assert fault["reason"] == "unreachable" and trans["new"] == "fault"
    assert trans["why"].startswith("unreachable")
    vent = next(r for r in rig.machine.log.records if r["kind"] == "vent")
    assert vent["ok"] is True


def test_daq_error_on_the_way_home_vents_and_stops() -> None:
    rig = make_rig()
    real = rig.backend.set_pressures

    failed = []

    def flaky(psi: np.ndarray) -> None:
        if rig.machine.state is S.RETURN_HOME and not failed:
            failed.append(psi)
            raise HardwareError("DAQmx error -50103: resource reserved")
        real(psi)

    rig.backend.set_pressures = flaky  # type: ignore[method-assign]
    report = run_targets(rig.machine.run_berry, [BerryTarget(1), BerryTarget(2)], rig.machine.log)
    assert rig.transitions(1)[-2:] == [S.RETURN_HOME, S.FAULT]
    assert report.stopped is FaultReason.HARDWARE_ERROR and rig.vented()
    assert report.berries[1].final_state is S.IDLE  # never attempted


def test_a_dead_daq_that_cannot_vent_is_logged_as_such() -> None:
    rig = make_rig()
    real = rig.backend.set_pressures

    def dead(psi: np.ndarray) -> None:
        if rig.clock.t >= 1.0:
            raise HardwareError("DAQmx error -200279: device removed")
        real(psi)

    rig.backend.set_pressures = dead  # type: ignore[method-assign]
    report = run_targets(rig.machine.run_berry, [BerryTarget(1)], rig.machine.log)
    assert report.stopped is FaultReason.HARDWARE_ERROR
    failed = [r for r in rig.machine.log.records if r["kind"] == "vent_failed"]
    assert failed and "could not vent" in failed[0]["error"]
    vent = next(r for r in rig.machine.log.records if r["kind"] == "vent")
    assert vent["ok"] is False  # the log says so: only the hardware e-stop can help now


def test_a_cube_lost_in_the_bush_backs_out_open_loop_before_the_vent() -> None:
    # The eye-to-hand camera stops in fine positioning: no pose to servo the back-out
    # on, so the arm ramps home the planned way, open loop, and vents there.
    rig = make_rig()
    rig.tracker.blind = lambda t: t >= 0.8
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.MARKER_LOST
    assert rig.transitions(1)[-3:] == [S.FINE_POSITIONING, S.RETURN_HOME, S.FAULT]
    incomplete = [r for r in rig.machine.log.records if r["kind"] == "retreat_incomplete"]
    assert len(incomplete) == 1 and "cube not seen" in incomplete[0]["detail"]
    assert commanded_before_the_vent(rig) == rig.machine.home.tolist()
    assert rig.vented() and "marker_lost" in rig.bank.vent_log[-1].reason


def test_a_berry_lost_in_the_bush_backs_out_on_the_cube_before_the_vent() -> None:
    rig = make_rig()
    rig.locator.hidden = lambda t: t >= 0.7
    rig.locator.max_age = 0.1
    result = rig.machine.run_berry(BerryTarget(1))
    assert result.fault is FaultReason.MARKER_LOST
    assert rig.transitions(1)[-3:] == [S.FINE_POSITIONING, S.RETURN_HOME, S.FAULT]
    assert not any(r["kind"] == "retreat_incomplete" for r in rig.machine.log.records)
    assert commanded_before_the_vent(rig) == rig.machine.home.tolist()
    assert rig.vented()
