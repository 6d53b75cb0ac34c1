"""Every command that can pressurise the arm takes SIGINT/SIGTERM the same way, from
``softarm.stops``: the arm vented, the stop logged, exit status 130/143, one
line on stderr and no traceback (issue 26, item 1). ``softarm calibrate`` had no handling
at all: SIGTERM killed it where it stood, skipping the ``finally`` that vents."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from child_signals import default_signals
from softarm import cli
from softarm.commands import calibrate, demo, harvest, identify
from softarm.stops import Interrupted, stop_arm


@pytest.fixture(autouse=True)
def _unhandled_sigterm_fails_the_test() -> Any:
    """Without the handling under test, SIGTERM would end the test runner itself."""

    def fail(signum: int, frame: object) -> None:
        raise AssertionError(f"{signal.Signals(signum).name} reached no handler")

    previous = signal.signal(signal.SIGTERM, fail)
    yield
    signal.signal(signal.SIGTERM, previous)


@pytest.mark.parametrize("module", [harvest, identify, calibrate, demo])
def test_every_command_that_drives_the_arm_has_the_shared_handling(module: Any) -> None:
    assert getattr(module.run, "drives_arm", False), module.__name__


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_calibrate_stopped_by_a_signal_says_so_and_exits_128_plus_n(
    sig: signal.Signals, status: int, tmp_path: Path
) -> None:
    """The issue's repro: `softarm calibrate --sim --poses 100 & sleep 2; kill $!`."""
    out = tmp_path / "m.toml"
    proc = subprocess.Popen(
        [sys.executable, "-m", "softarm", "calibrate", "--sim", "--poses", "100", "--out",
         str(out)],
        stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True, preexec_fn=default_signals,
    )  # fmt: skip
    try:
        assert proc.stderr is not None
        line = proc.stderr.readline()  # "pose 10/100 measured": it is driving the arm
        assert line.startswith("pose "), line
        proc.send_signal(sig)
        _, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == status, stderr
    assert "Traceback" not in stderr
    assert f"softarm calibrate: interrupted by {sig.name}: arm vented" in stderr
    assert not out.exists()


class _Plant:
    """A simulated plant that records its commands and delivers SIGTERM to this process
    after ``stop_after`` steps, as `kill` would mid-calibration."""

    def __init__(self, stop_after: int) -> None:
        self.commands: list[np.ndarray] = []
        self.steps = 0
        self.stop_after = stop_after

    def command_pressures(self, psi: np.ndarray) -> None:
        self.commands.append(np.array(psi))

    def advance(self, dt: float) -> None:
        self.steps += 1
        if self.steps == self.stop_after:
            os.kill(os.getpid(), signal.SIGTERM)

    def pose(self) -> np.ndarray:
        return np.eye(4)


def test_calibrate_sim_vents_the_plant_on_sigterm(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from softarm.calibration import sim

    plant = _Plant(stop_after=40)
    monkeypatch.setattr(sim, "build_plant", lambda *a, **k: plant)
    out = tmp_path / "m.toml"
    status = cli.main(["calibrate", "--sim", "--poses", "22", "--out", str(out), "--quiet"])
    assert status == 143
    assert plant.commands[-2].max() > 0.0  # it was pressurised ...
    np.testing.assert_array_equal(plant.commands[-1], 0.0)  # ... and is vented
    assert not out.exists()
    err = capsys.readouterr().err
    assert "SIGTERM" in err and "vented" in err and "Traceback" not in err


def test_identify_stopped_by_sigterm_closes_the_rig(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from softarm.identification.rig import SimIdentificationRig

    closed: list[str] = []
    advance, close = SimIdentificationRig.advance, SimIdentificationRig.close
    steps = [0]

    def advance_then_kill(self: SimIdentificationRig) -> None:
        advance(self)
        steps[0] += 1
        if steps[0] == 50:
            os.kill(os.getpid(), signal.SIGTERM)

    def close_and_note(self: SimIdentificationRig) -> None:
        close(self)
        closed.append(self.bank.vent_log[-1].reason)

    monkeypatch.setattr(SimIdentificationRig, "advance", advance_then_kill)
    monkeypatch.setattr(SimIdentificationRig, "close", close_and_note)
    out = tmp_path / "id.json"
    status = cli.main(["identify", "--sim", "--budget", "30", "--out", str(out), "--quiet"])
    assert status == 143
    assert closed == ["close"] and not out.exists()
    err = capsys.readouterr().err
    assert "softarm identify: interrupted by SIGTERM: arm vented" in err


class _Log:
    def __init__(self) -> None:
        self.records: list[dict[str, Any]] = []
        self.closed = False

    def event(self, kind: str, **fields: Any) -> None:
        self.records.append({"kind": kind, **fields})

    def close(self) -> None:
        self.closed = True


def test_a_dead_driver_still_completes_the_log() -> None:
    def dead(reason: str) -> None:
        raise OSError("port gone")

    log = _Log()
    assert stop_arm(dead, Interrupted(signal.SIGTERM), log) is False
    assert [r["kind"] for r in log.records] == ["vent_failed", "interrupted"]
    assert log.records[-1]["vented"] is False and log.records[-1]["exit_status"] == 143
    assert log.closed


def test_a_sweep_trial_stopped_by_its_worker_vents_and_logs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A Ray worker's SIGTERM handler exits with the signal number: the trial's arm is
    vented and the stop recorded on the way out."""
    from softarm.harvest.machine.harvest_machine import HarvestMachine
    from softarm.harvest.rigs.sim import rig as sim_rig
    from softarm.sweep import parse_spec
    from softarm.sweep.trial import run_trial

    rigs: list[Any] = []
    build = sim_rig.build_sim_rig
    monkeypatch.setattr(sim_rig, "build_sim_rig", lambda o: rigs.append(build(o)) or rigs[-1])

    def killed(self: HarvestMachine, target: Any) -> Any:
        os.kill(os.getpid(), signal.SIGTERM)
        raise AssertionError("the signal did not arrive")

    monkeypatch.setattr(HarvestMachine, "run_berry", killed)
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(signum))
    try:
        trial = parse_spec({"sweep": {"seeds": [0], "berries": 1, "plant": {}}}).trials()[0]
        with pytest.raises(SystemExit):
            run_trial(trial)
    finally:
        signal.signal(signal.SIGTERM, previous)
    vents = rigs[0].bank.vent_log
    assert vents[-1].reason == "stopped by SIGTERM"
