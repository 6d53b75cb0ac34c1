"""Silent or missing pieces (issue 39, item 6): `softarm tune` reports progress off a
terminal, `camera calibrate` names a missing folder, `camera board` writes the board it
expects, opening an absent camera prints no OpenCV log lines, and every output (file or
folder) creates the folders it names."""

from __future__ import annotations

import argparse
import io
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from softarm import cli
from softarm.commands._args import output_file
from softarm.files.write import write_text


def test_tune_prints_a_line_per_candidate_when_not_on_a_terminal() -> None:
    tune = pytest.importorskip("ray.tune")
    from softarm.sweep.tune import _bar_callback

    lines = io.StringIO()
    bar = _bar_callback(tune, 2, 3, enabled=True, file=io.StringIO(), lines=lines)
    assert bar.bar.disable  # not a terminal: no bar drawn
    bar.on_trial_complete(1, [], SimpleNamespace(trial_id="a", last_result={"score": 0.75}))
    assert "tune: 1/2 candidates, best 0.7500" in lines.getvalue()
    quiet = io.StringIO()
    bar = _bar_callback(tune, 2, 3, enabled=False, file=io.StringIO(), lines=quiet)
    bar.on_trial_complete(1, [], SimpleNamespace(trial_id="a", last_result={"score": 0.75}))
    assert quiet.getvalue() == ""  # --quiet / --no-progress


def test_calibrate_names_a_missing_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    argv = ["camera", "calibrate", "c2_shots/", "--squares", "7", "5", "--square", "0.04"]
    assert cli.main([*argv, "--marker", "0.03", "--out", "c2"]) == 2
    err = capsys.readouterr().err
    assert "'c2_shots': no such file or folder" in err and "as an image" not in err


def test_camera_board_writes_the_board_calibrate_detects(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import cv2

    from softarm.vision.calibration import charuco_board

    out = tmp_path / "boards" / "board.png"  # a missing folder is made
    assert cli.main(["camera", "board", "--out", str(out), "--dpi", "100"]) == 0
    assert "print at 100 % scale" in capsys.readouterr().out
    image = cv2.imread(str(out), cv2.IMREAD_GRAYSCALE)
    detector = cv2.aruco.CharucoDetector(charuco_board((7, 5), 0.04, 0.03, "DICT_4X4_50"))
    corners = detector.detectBoard(image)[0]
    assert corners is not None and len(corners) == 6 * 4  # every inner corner


def test_an_absent_camera_prints_no_opencv_log_lines() -> None:
    code = (
        "from softarm.errors import HardwareUnavailableError\n"
        "from softarm.hardware.camera import OpenCVCamera\n"
        "try:\n"
        "    OpenCVCamera(57)\n"
        "except HardwareUnavailableError as exc:\n"
        "    print('typed:', exc)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.stdout.startswith("typed:")
    assert "WARN" not in done.stderr and "cap_v4l" not in done.stderr, done.stderr


def test_a_file_option_accepts_missing_folders_and_creates_nothing(tmp_path: Path) -> None:
    path = tmp_path / "a" / "b" / "r.json"
    assert output_file(str(path)) == path
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "f").write_text("")
    with pytest.raises(argparse.ArgumentTypeError, match="is a file"):
        output_file(str(tmp_path / "f" / "r.json"))


def test_outputs_create_their_folders(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["config", "init", str(tmp_path / "cfg" / "hw.toml")]) == 0
    assert (tmp_path / "cfg" / "hw.toml").is_file()
    write_text(tmp_path / "x" / "y" / "r.json", "{}")
    assert (tmp_path / "x" / "y" / "r.json").read_text() == "{}"


def test_tune_out_is_checked_as_a_file_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "f").write_text("")
    with pytest.raises(SystemExit) as exit_:
        cli.main(["tune", "spec.toml", "--out", str(tmp_path / "f" / "gains.toml")])
    assert exit_.value.code == 2 and "argument --out" in capsys.readouterr().err
