"""Issue 26, items 4, 5, 6, 9 and 10: the structure and ranges of model.toml, id.json and
camera files, a run log whose last line was cut off, and calibrate's arguments."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import softarm
from softarm.calibration import Calibration
from softarm.calibration.metrics import PoseErrorStats
from softarm.errors import ConfigError, ParameterError
from softarm.harvest.records.log import CUT_MARK, HarvestLog, read_log
from softarm.identified_plant import load_identified
from softarm.vision.camera_model import CameraModel
from test_files_hardening import cli


def _model() -> dict[str, Any]:
    fit = PoseErrorStats(30, 0.1, 0.2, 0.3, 0.01, 0.02, 0.03)
    cal = Calibration(softarm.SoftArm.blackberry(), np.ones(9), fit)
    return tomllib.loads(cal.to_toml())


def _set(data: dict[str, Any], key: str, value: Any) -> dict[str, Any]:
    *parents, last = key.split(".")
    node = data
    for name in parents:
        node = node[name][0] if name == "sections" else node[name]
    node[last] = value
    return data


@pytest.mark.parametrize(
    ("key", "value", "named"),
    [
        ("arm", 5, "arm = 5: must be a table"),
        ("fit", 5, "fit = 5: must be a table"),
        ("arm.sections.radius", "0.028", "arm.sections[0].radius = '0.028'"),
        ("fit.position_median_mm", float("nan"), "fit.position_median_mm = nan"),
        ("fit.samples", 1.5, "fit.samples = 1.5: must be an integer"),
        ("converged", "no", "converged = 'no': must be true or false"),
        ("format", True, "format = True"),
        ("actuators.offset", [1e300] * 9, "actuators.offset[0] = 1e+300"),
        ("actuators.gain", [1e-300] * 9, "actuators.gain[0] = 1e-300"),
        ("actuators.gain", [1.0] * 8, "actuators.gain: must hold 9 values"),
        ("parameters", {"r0": "x"}, "parameters.r0 = 'x'"),
    ],
)
def test_malformed_model_is_one_line_naming_the_key(key: str, value: Any, named: str) -> None:
    with pytest.raises(ConfigError) as err:
        Calibration.from_dict(_set(_model(), key, value), "m.toml")
    assert str(err.value).startswith("m.toml: ") and named in str(err.value)
    assert "\n" not in str(err.value)


def test_a_saved_model_reads_back() -> None:
    cal = Calibration.from_dict(_model(), "m.toml")
    assert cal.converged is True and cal.fit.samples == 30


@pytest.mark.parametrize(
    ("key", "value"),
    [("tau_s", 1e16), ("tau_s", 0.0), ("metres_per_psi", 1e-300), ("dead_time_s", 1e300),
     ("hysteresis_psi", 1e3)],
)  # fmt: skip
def test_id_json_values_are_bounded(tmp_path: Path, key: str, value: float) -> None:
    """tau_s = 1e16 ended in a ZeroDivisionError in the lag model (issue 26 item 5)."""
    data = {"tau_s": [0.1] * 9, "metres_per_psi": [4.7e-4] * 9}
    data |= {"hysteresis_psi": [1.0] * 9, "dead_time_s": [0.0] * 9, key: [value] * 9}
    (tmp_path / "id.json").write_text(json.dumps(data))
    with pytest.raises(ConfigError, match=rf"id\.json: {key}\[0\] = .*must be a finite number"):
        load_identified(tmp_path / "id.json")


OPENCV = """%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]
"""
ROS = """image_width: 640
image_height: 480
camera_name: cam
camera_matrix:
  rows: 3
  cols: 3
  data: [500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0]
"""
JSON = {
    "format": "softarm.camera/1",
    "image_size": [640, 480],
    "camera_matrix": [[500, 0, 320], [0, 500, 240], [0, 0, 1]],
}


@pytest.mark.parametrize(
    ("name", "text", "named"),
    [
        ("rows.yml", OPENCV.replace("rows: 3", "rows: 2"), "camera_matrix"),
        ("dt.yml", OPENCV.replace("dt: d", "dt: x"), "camera_matrix"),
        ("scalar.yml", "%YAML:1.0\n---\ncamera_matrix: 5\n", "camera_matrix"),
        ("nan.yml", OPENCV.replace("width: 640", "width: .nan"), "image_width"),
        ("ros.yaml", ROS.replace("rows: 3", "rows: .nan"), "camera_matrix.rows"),
        ("str.yaml", ROS.replace("[500.0", '["x"'), "camera_matrix.data[0]"),
        ("size.json", json.dumps(JSON | {"image_size": [1]}), "image_size"),
        ("frac.json", json.dumps(JSON | {"image_size": [1.9, 2.9]}), "image_size"),
        ("fx.json", json.dumps(JSON | {"camera_matrix": [[1e-300, 0, 1], [0, 1, 1], [0, 0, 1]]}),
         "fx"),
    ],
)  # fmt: skip
def test_malformed_camera_file_is_one_line(
    tmp_path: Path, name: str, text: str, named: str
) -> None:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        CameraModel.load(path)
    assert name in str(err.value) and named in str(err.value) and "\n" not in str(err.value)


def test_the_valid_camera_files_still_load(tmp_path: Path) -> None:
    for name, text in (("a.yml", OPENCV), ("b.yaml", ROS), ("c.json", json.dumps(JSON))):
        (tmp_path / name).write_text(text)
        assert CameraModel.load(tmp_path / name).image_size == (640, 480)


def test_a_singular_camera_matrix_is_refused() -> None:
    with pytest.raises(ParameterError, match="fx"):
        CameraModel(np.array([[1e-300, 0, 1], [0, 1, 1], [0, 0, 1]]))


def test_a_run_appended_after_a_cut_line_reads_with_both_runs(tmp_path: Path) -> None:
    """Issue 26 item 9: a power cut left the last line half-written; the next run's first
    record used to join it, and the log was unreadable in the middle."""
    path = tmp_path / "run.jsonl"
    with HarvestLog(path) as first:
        first.event("transition", t=0.0)
        first.event("transition", t=1.0)
    path.write_bytes(path.read_bytes()[:-7])  # the cut
    with HarvestLog(path) as second:
        second.event("transition", t=2.0)
    records = list(read_log(path))
    assert [r.get("t") for r in records] == [0.0, None, 2.0]
    assert records[1]["kind"] == CUT_MARK


def test_a_complete_log_gets_no_mark(tmp_path: Path) -> None:
    path = tmp_path / "run.jsonl"
    for t in (0.0, 1.0):
        with HarvestLog(path) as log:
            log.event("transition", t=t)
    assert [r["t"] for r in read_log(path)] == [0.0, 1.0]


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["--seed", "-5000"], "--seed"),
        (["--poses", "5"], "--poses"),
        (["--out", "/proc/nope/m.toml"], "--out"),  # a folder that cannot be made
        (["--out", "{tmp}"], "--out"),
        (["--plant", "{tmp}/absent.toml"], "--plant"),
    ],
)
def test_calibrate_refuses_bad_arguments_before_any_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], option: str
) -> None:
    """Issue 26 item 10: --seed -5000 was a traceback, --out /missing/m.toml failed after
    the fit had run. Now each is refused while parsing: exit 2, one line, nothing written."""
    argv = ["calibrate", "--sim", *(a.format(tmp=tmp_path) for a in args)]
    status, err = cli(argv, capsys)
    assert status == 2 and err.count("\n") == 1 and f"argument {option}" in err
    assert "pose " not in err and list(tmp_path.iterdir()) == []
