"""examples/hardware_bringup.py: exits 0 with no hardware, plans with --dry-run, reports
a present-but-failing device with status 1 and a bad config with status 2."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from fake_arduino import FakeArduino

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "examples" / "hardware_bringup.py"


def load_script() -> types.ModuleType:
    spec = importlib.util.spec_from_file_location("hardware_bringup", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def fake_drivers(monkeypatch: pytest.MonkeyPatch, present: bool) -> list[str]:
    """Install fake nidaqmx and cv2 modules; returns the log of what was opened."""
    opened: list[str] = []

    class Task:
        def __init__(self) -> None:
            opened.append("daq")
            self.ao_channels = types.SimpleNamespace(add_ao_voltage_chan=self.add)

        def add(self, name: str, min_val: float, max_val: float) -> None:
            if not present:
                raise RuntimeError("NI-DAQmx: device Dev1 not found")

        def write(self, data: list[float], auto_start: bool) -> None:
            assert all(v == 0.0 for v in data)  # bring-up only ever vents

        def close(self) -> None:
            pass

    class Capture:
        def __init__(self, source: object) -> None:
            opened.append(f"camera {source}")

        def isOpened(self) -> bool:
            return present

        def read(self) -> tuple[bool, np.ndarray]:
            return True, np.zeros((2, 2, 3), np.uint8)

        def release(self) -> None:
            pass

    monkeypatch.setitem(sys.modules, "nidaqmx", types.SimpleNamespace(Task=Task))
    monkeypatch.setitem(sys.modules, "cv2", types.SimpleNamespace(VideoCapture=Capture))
    return opened


def test_exits_zero_with_no_hardware_attached(tmp_path: Path) -> None:
    # This interpreter's path: softarm from wherever the tests import it (the wheel that
    # `make test` installs, or the editable .venv), never the checkout's python/ put first.
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--port", str(tmp_path / "ttyNONE")],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "arduino            absent" in proc.stdout
    assert "would have: open" in proc.stdout and "ttyNONE" in proc.stdout


def test_absent_drivers_in_process(monkeypatch: pytest.MonkeyPatch, capsys, tmp_path) -> None:
    opened = fake_drivers(monkeypatch, present=False)
    assert load_script().main(["--port", str(tmp_path / "none")]) == 0
    out = capsys.readouterr().out
    assert out.count(" absent\n") == 4 and "Dev1 not found" in out
    assert opened == ["daq", "camera 0", "camera 1"]


def test_dry_run_opens_nothing(monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    opened = fake_drivers(monkeypatch, present=True)
    assert load_script().main(["--dry-run"]) == 0
    out = capsys.readouterr().out
    assert opened == [] and out.count(" planned\n") == 4
    assert "would open NI-DAQmx Dev1/ao0..Dev1/ao8 at 0.0-5.0 V" in out


def test_everything_present(monkeypatch, capsys, arduino: FakeArduino, tmp_path) -> None:
    fake_drivers(monkeypatch, present=True)
    config = tmp_path / "arm.toml"
    text = (ROOT / "python/softarm/data/blackberry.toml").read_text()
    config.write_text(text.replace("startup_delay_s = 2.0", "startup_delay_s = 0.0"))
    assert load_script().main(["--config", str(config), "--port", arduino.path]) == 0
    out = capsys.readouterr().out
    assert out.count(" ok\n") == 5 and "firmware 'softarm-fake 2'" in out


def test_present_but_failing_device(monkeypatch, capsys, arduino: FakeArduino, tmp_path) -> None:
    fake_drivers(monkeypatch, present=False)
    arduino.corrupt = 1000
    config = tmp_path / "arm.toml"
    text = (ROOT / "python/softarm/data/blackberry.toml").read_text()
    config.write_text(
        text.replace("timeout_s = 0.5\nretries = 2", "timeout_s = 0.2\nretries = 0").replace(
            "startup_delay_s = 2.0", "startup_delay_s = 0.0"
        )
    )
    assert load_script().main(["--config", str(config), "--port", arduino.path]) == 1
    assert "present but failing: bad checksum" in capsys.readouterr().out


def test_invalid_config(capsys, tmp_path: Path) -> None:
    config = tmp_path / "arm.toml"
    config.write_text("[arm]\nsections = []\n")
    assert load_script().main(["--config", str(config)]) == 2
    assert "arm.sections must be a non-empty array" in capsys.readouterr().out
