"""Ctrl-C in the middle of `softarm tune`: exit status 130 (not 2, not 0 with the
candidates so far), no gains file written, a one-line message."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest

from child_signals import default_signals

pytest.importorskip("ray.tune")
pytest.importorskip("optuna")

DRIVER = """\
import os, signal, sys, time
import softarm.sweep.tune as tune_module
from softarm import cli

DRIVER_PID = os.getpid()

def interrupting(trial):
    os.kill(DRIVER_PID, signal.SIGINT)  # Ctrl-C at the driver, while a candidate runs
    time.sleep(30)
    return []

tune_module.run_trial_rows = interrupting
sys.exit(cli.main(["tune", sys.argv[1], "--out", sys.argv[2], "--cpus", "1", "--samples", "2",
                   "-q"]))
"""

SPEC = """\
[sweep]
seeds = [0]
berries = 1

[tune]
samples = 2
"""


def test_ctrl_c_exits_130_without_gains(tmp_path: Path) -> None:
    script = tmp_path / "driver.py"
    script.write_text(DRIVER)
    spec = tmp_path / "spec.toml"
    spec.write_text(SPEC)
    gains = tmp_path / "gains.toml"
    proc = subprocess.run(
        [sys.executable, str(script), str(spec), str(gains)],
        capture_output=True, text=True, timeout=240, preexec_fn=default_signals,
    )  # fmt: skip
    assert proc.returncode == 128 + signal.SIGINT, proc.stderr[-3000:]
    assert "interrupted" in proc.stderr
    assert not gains.exists()
