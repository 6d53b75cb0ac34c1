"""hw.toml's paths resolve against its folder, ``config check`` opens every file the
config names, a file together with inline values is refused, and the hardware harvest
opens its log before anything else (issue 24, item 4). Each bad configuration is one
line naming the key or the file."""

from __future__ import annotations

import re
import signal
from pathlib import Path

import numpy as np
import pytest

from softarm import cli
from softarm.commands.config import template
from softarm.config import load_config
from softarm.errors import ConfigError
from softarm.harvest.records.log import read_log
from softarm.vision import CameraModel
from softarm.vision.camera_model import camera_from_config

CAMERA = CameraModel.ideal(700.0, 640, 480, [0.01, 0.0, 0.0, 0.0, 0.0])


def _ready() -> str:
    """The template with its calibration placeholders uncommented: a complete config."""
    return re.sub(r"(?m)^# ((T_C1_base|T_C2_EE|matrix) = )", r"\1", template())


def _with_c1_file(name: str) -> str:
    """The complete config, its C1 intrinsics from the file ``name``."""
    text = _ready()
    start = text.index("[calibration.c1]")
    end = text.index("[calibration.c2]")
    c1 = f'[calibration.c1]\nsource = 0\nfile = "{name}"\n\n'
    return text[:start] + c1 + text[end:]


def _write(folder: Path, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "hw.toml"
    path.write_text(text)
    return path


def _check(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, list[str]]:
    status = cli.main(["config", "check", str(path)])
    return status, capsys.readouterr().err.strip().splitlines()


def test_camera_file_resolves_against_the_config_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _write(tmp_path / "rig", _with_c1_file("c1.yaml"))
    CAMERA.save(tmp_path / "rig" / "c1.yaml")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # the working directory has no c1.yaml
    config = load_config(path)
    assert config.calibration.c1.file == "c1.yaml"  # kept as written
    model = camera_from_config(config.calibration.c1, "c1")
    np.testing.assert_allclose(model.matrix, CAMERA.matrix)


def test_relative_source_resolves_and_urls_are_kept(tmp_path: Path) -> None:
    text = _ready().replace("source = 1", 'source = "videos/c2.mp4"', 1)
    text = text.replace("source = 0", 'source = "rtsp://cam/1"', 1)
    config = load_config(_write(tmp_path, text))
    assert config.calibration.c2.device == str(tmp_path / "videos" / "c2.mp4")
    assert config.calibration.c1.device == "rtsp://cam/1"


def test_round_trip_keeps_the_path_as_written(tmp_path: Path) -> None:
    from softarm.config import dump_config

    CAMERA.save(tmp_path / "c1.json")
    config = load_config(_write(tmp_path, _with_c1_file("c1.json")))
    assert 'file = "c1.json"' in dump_config(config)
    assert "folder" not in dump_config(config)


@pytest.mark.parametrize("inline", ["matrix = [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1]]",
                                    "distortion = [0.0, 0.0, 0.0, 0.0]"])  # fmt: skip
def test_file_and_inline_values_conflict(tmp_path: Path, inline: str) -> None:
    text = _with_c1_file("c1.json").replace('file = "c1.json"', f'file = "c1.json"\n{inline}')
    key = inline.split(" ")[0]
    with pytest.raises(ConfigError, match=rf"calibration\.c1\.{key} and calibration\.c1\.file"):
        load_config(_write(tmp_path, text))


def test_check_reports_a_missing_camera_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    status, err = _check(_write(tmp_path, _with_c1_file("c1.yaml")), capsys)
    assert status == 2
    assert len(err) == 1
    assert "calibration.c1.file" in err[0] and "c1.yaml" in err[0] and "no such file" in err[0]


def test_check_reports_a_broken_camera_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "c1.yaml").write_text("camera_matrix: [1, 2\n")
    status, err = _check(_write(tmp_path, _with_c1_file("c1.yaml")), capsys)
    assert status == 2 and len(err) == 1
    assert "calibration.c1.file" in err[0] and "c1.yaml" in err[0]


def test_check_reports_each_problem_on_its_own_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "c1.json").write_text('{"format": "softarm.camera/1"}')
    text = _with_c1_file("c1.json").replace("matrix = [[600.0", "matrix = [[-600.0")  # C2's fx < 0
    text += '\n[plant_model]\nfile = "id.json"\n'
    status, err = _check(_write(tmp_path, text), capsys)
    assert status == 2
    assert len(err) == 3, err
    assert "calibration.c1.file" in err[0] and "camera_matrix is required" in err[0]
    assert "calibration.c2" in err[1] and "fx" in err[1]
    assert "plant_model.file" in err[2] and "id.json" in err[2]


def test_check_passes_with_good_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    CAMERA.save(tmp_path / "c1.yml")
    status = cli.main(["config", "check", str(_write(tmp_path, _with_c1_file("c1.yml")))])
    assert status == 0, capsys.readouterr().err
    assert "ready" in capsys.readouterr().out


def test_harvest_names_the_camera_file_it_cannot_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _write(tmp_path, _with_c1_file("c1.yaml"))
    assert cli.main(["harvest", "--config", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "calibration.c1.file" in err[0] and "c1.yaml" in err[0]


def test_a_stop_during_set_up_is_in_the_log(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """SIGTERM while the config is read: the log, opened first, records it."""
    from softarm import stops as _signals
    from softarm.commands import harvest

    def stopped(args: object) -> None:
        _signals._raise(signal.SIGTERM, None)

    monkeypatch.setattr(harvest, "_hardware_config", stopped)
    path = _write(tmp_path, _ready())
    log = tmp_path / "run.jsonl"
    assert cli.main(["harvest", "--config", str(path), "--log", str(log)]) == 143
    records = list(read_log(log))
    assert records[-1]["kind"] == "interrupted" and records[-1]["signal"] == "SIGTERM"
    assert f"log {log}" in capsys.readouterr().err


def test_the_exit_message_names_no_log_it_did_not_write(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A stop before the log is opened (reading --gains) must not name the log."""
    from softarm import stops as _signals
    from softarm.commands import harvest

    def stopped(args: object) -> None:
        _signals._raise(signal.SIGINT, None)

    monkeypatch.setattr(harvest, "_gains", stopped)
    log = tmp_path / "run.jsonl"
    status = cli.main(["harvest", "--config", str(_write(tmp_path, _ready())), "--log", str(log)])
    assert status == 130
    err = capsys.readouterr().err
    assert "SIGINT" in err and "run.jsonl" not in err
    assert not log.exists()
