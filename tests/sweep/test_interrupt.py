"""Ctrl-C (or SIGTERM) in the middle of a sweep: the driver stops within seconds, the table
holds every trial that finished, and none of the Ray processes it started is left running."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from child_signals import default_signals

pytest.importorskip("ray")
pytest.importorskip("pyarrow")
import pyarrow.parquet as pq

DRIVER = """\
import sys, time
import ray
from softarm.sweep import parse_spec
from softarm.sweep.runner import run_sweep
from softarm.sweep.trial import BERRY_COLUMNS

def slow(trial):
    time.sleep(1.5)
    row = dict.fromkeys(BERRY_COLUMNS)
    row.update(trial_id=trial.trial_id, seed=trial.seed, **trial.plant, berry=0, harvested=True)
    return [row]

def on_trial(trial, rows):
    # Tell the test which Ray session this is, once the first trial is in the table.
    print("SESSION", ray._private.worker._global_node.get_session_dir_path(), flush=True)

spec = parse_spec({"sweep": {"seeds": list(range(12)), "berries": 1,
                             "plant": {"pressure_tau": [0.08]}}})
out = run_sweep(spec, sys.argv[1], cpus=1, trial_fn=slow, progress=False, on_trial=on_trial)
print("INTERRUPTED" if out.interrupted else "COMPLETED", out.ran, out.signal, flush=True)
"""


def _processes_mentioning(text: str) -> list[str]:
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            cmd = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        if text in cmd:
            found.append(f"{pid}: {cmd[:120]}")
    return found


@pytest.mark.skipif(sys.platform != "linux", reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_keeps_finished_trials_and_stops_ray(tmp_path: Path, sig: signal.Signals) -> None:
    script = tmp_path / "driver.py"
    script.write_text(DRIVER)
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, str(script), str(out)], stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, preexec_fn=default_signals,
    )  # fmt: skip
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()  # blocks until the first trial is written
        assert line.startswith("SESSION "), (line, proc.stderr.read() if proc.stderr else "")
        session = Path(line.split(maxsplit=1)[1].strip()).name
        proc.send_signal(sig)
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, stderr
    last = stdout.strip().splitlines()[-1]
    assert last.startswith("INTERRUPTED"), stdout
    ran = int(last.split()[1])
    assert int(last.split()[2]) == sig  # SIGTERM is told apart (exit status 143)
    assert 1 <= ran < 12
    rows = pq.read_table(out / "results.parquet").to_pylist()
    assert len(rows) == ran  # every finished trial, and only those
    # Ray's processes of that session (GCS, raylet, workers) are gone.
    deadline = time.monotonic() + 10.0
    while _processes_mentioning(session) and time.monotonic() < deadline:
        time.sleep(0.5)
    assert not _processes_mentioning(session)
