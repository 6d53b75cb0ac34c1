"""SIGTERM and SIGINT on a running ``softarm harvest --sim``: the arm is vented, the log
ends with a record naming the signal, the exit status is 128 + the signal number, and no
traceback is printed. Python's default SIGTERM action kills the process with none of
this (no vent, no record), and SIGINT alone prints a KeyboardInterrupt traceback."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from child_signals import default_signals

#: Generous: the run must have started stepping before the signal, on a loaded CI box.
START_TIMEOUT_S = 180.0


def _records(path: Path) -> list[dict]:
    if not path.exists():
        return []
    lines = path.read_text().splitlines()
    out = []
    for line in lines:
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:  # a line being written
            break
    return out


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_signal_vents_logs_and_exits(sig: signal.Signals, status: int, tmp_path: Path) -> None:
    log = tmp_path / "run.jsonl"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "softarm", "harvest", "--sim", "--berries", "3", "--log", str(log)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        preexec_fn=default_signals,
    )
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while not any(r["kind"] == "step" for r in _records(log)):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "the harvest never started stepping"
            time.sleep(0.2)
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == status, (out, err)
    assert "Traceback" not in err
    assert sig.name in err and "vented" in err
    records = _records(log)
    last = records[-1]
    assert last["kind"] == "interrupted"
    assert last["signal"] == sig.name and last["vented"] is True
    assert last["exit_status"] == status
    vents = [r for r in records if r["kind"] == "vent"]
    assert vents and sig.name in vents[-1]["reason"]


class _FakeMachine:
    def __init__(self) -> None:
        self.vents: list[str] = []
        self.actuator = self

    def vent(self, reason: str) -> None:
        self.vents.append(reason)

    def run(self, berries: object) -> object:
        from softarm.stops import Interrupted

        raise Interrupted(signal.SIGTERM)  # as the handler does, mid-run


class _FakeRig:
    def __init__(self) -> None:
        self.machine = _FakeMachine()
        self.closed = False

    def close(self) -> None:
        self.closed = True

    def run(self, berries: object) -> object:
        return self.machine.run(berries)  # the hardware rig's harvest loop, stopped mid-run


def test_hardware_run_stopped_by_sigterm_vents_closes_and_logs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """On hardware the devices are released (the `finally` runs) and the log says why."""
    import re

    from softarm import cli
    from softarm.commands.config import template
    from softarm.harvest.rigs.hardware import rig as hw_rig

    config = tmp_path / "hw.toml"
    config.write_text(re.sub(r"(?m)^# ((T_C1_base|T_C2_EE|matrix) = )", r"\1", template()))
    rig = _FakeRig()
    monkeypatch.setattr(hw_rig, "build_hardware_rig", lambda *a, **k: rig)
    log = tmp_path / "run.jsonl"
    status = cli.main(["harvest", "--config", str(config), "--log", str(log)])
    assert status == 143
    assert rig.closed and rig.machine.vents == ["stopped by SIGTERM"]
    last = _records(log)[-1]
    assert last["kind"] == "interrupted" and last["signal"] == "SIGTERM"
    err = capsys.readouterr().err
    assert "SIGTERM" in err and "Traceback" not in err
