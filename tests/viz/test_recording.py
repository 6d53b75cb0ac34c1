"""Recordings open with the rerun SDK: a 1-berry simulated harvest recorded live
(``harvest --sim --record``), its run log replayed (``softarm replay``), and the records'
checks. Skipped without rerun-sdk (the ``viz`` extra)."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("rerun")

from softarm.cli import main
from softarm.errors import InputError, ShapeError
from softarm.harvest import read_log
from softarm.viz.replay import replay

from .rrd import column, read_rrd, sim_seconds

LABELS, SCALARS = "LineStrips2D:labels", "Scalars:scalars"


@pytest.fixture(scope="module")
def harvest_run(tmp_path_factory: pytest.TempPathFactory):
    """One berry harvested with both a run log and a live recording."""
    folder = tmp_path_factory.mktemp("run")
    log, rrd = folder / "run.jsonl", folder / "run.rrd"
    args = ["harvest", "--sim", "--berries", "1", "--seed", "0", "-q"]
    assert main([*args, "--log", str(log), "--record", str(rrd)]) == 0
    return log, rrd


@pytest.mark.slow
def test_live_recording_holds_the_scene_cameras_states_and_errors(harvest_run) -> None:
    log, rrd = harvest_run
    rows = read_rrd(rrd)
    for entity in (
        "/world/canes", "/world/berries", "/world/arm/true/backbone", "/world/arm/true/gripper",
        "/world/arm/true/gripper/outline", "/world/arm/model/backbone", "/world/c1/image",
        "/world/c2/image", "/world/c1/image/detections", "/world/c2/image/detections",
        "/harvest/state", "/harvest/state_index", "/errors/position_mm",
        "/errors/true_gap_mm", "/errors/true_grasp_mm",
    ):  # fmt: skip
        assert entity in rows, entity
    berry = rows["/world/berries"][0]
    assert berry["Points3D:labels"] == ["tag 10"]
    # The six transitions of a harvested berry, on the simulated clock, in order.
    records = list(read_log(log))
    transitions = [r for r in records if r["kind"] == "transition"]
    texts = [r for r in rows["/harvest/state"] if "->" in r["TextLog:text"][0]]
    assert len(texts) == len(transitions) == 6
    assert [sim_seconds(r) for r in texts] == pytest.approx([r["t"] for r in transitions])
    assert "-> done" in texts[-1]["TextLog:text"][0]
    # The true arm is drawn at every step of the clock up to the end of the run.
    end = max(r["t"] for r in records if "t" in r)
    times = sorted(sim_seconds(r) for r in rows["/world/arm/true/backbone"])
    assert times[0] == 0.0 and times[-1] >= end
    # The marker cube (ids 0-3) and the berry's tag (10) are detected in C1, the tag in C2.
    c1 = {x for _, labels in column(rows, "/world/c1/image/detections", LABELS) for x in labels}
    c2 = {x for _, labels in column(rows, "/world/c2/image/detections", LABELS) for x in labels}
    assert c1 & {"id 0", "id 1", "id 2", "id 3"} and "id 10" in c1 and "id 10" in c2


@pytest.mark.slow
def test_replay_of_the_run_log(harvest_run, tmp_path, capsys) -> None:
    log, _ = harvest_run
    out = tmp_path / "replay.rrd"
    assert main(["replay", str(log), "--record", str(out)]) == 0
    n = len(list(read_log(log)))
    assert f"{n} records" in capsys.readouterr().out
    rows = read_rrd(out)
    steps = [r for r in read_log(log) if r["kind"] == "step"]
    assert len(rows["/world/arm/model/backbone"]) == len(steps)
    measured = [r for r in steps if r["position_error_m"] is not None]
    errors = column(rows, "/errors/position_mm", SCALARS)
    assert [e[0] for _, e in errors] == pytest.approx(
        [1e3 * r["position_error_m"] for r in measured]
    )
    (berries,) = rows["/world/berries"]
    assert berries["Points3D:labels"] == ["tag 10"]


def _write(path, records) -> None:
    path.write_text("".join(json.dumps(r) + "\n" for r in records))


def test_replay_of_a_synthetic_log(tmp_path) -> None:
    log = tmp_path / "run.jsonl"
    _write(log, [
        {"kind": "transition", "t": 0.0, "berry": 12, "old": "idle", "new": "idle", "why": "new"},
        {"kind": "step", "t": 0.05, "state": "initial_placement", "berry": 12, "q": [0.01] * 9,
         "pose": None, "target": [0.0, 0.3, 0.4], "camera": "eye_to_hand", "target_age_s": 0.0,
         "goal": None, "position_error_m": 0.012, "orientation_error_rad": 0.1,
         "saturated": False},
        {"kind": "fault", "t": 0.1, "berry": 12, "reason": "marker_lost", "detail": "lost"},
        {"kind": "berry_result", "tag_id": 12, "target": [0.0, 0.3, 0.4], "harvested": False,
         "fault": "marker_lost"},
    ])  # fmt: skip
    out = tmp_path / "out.rrd"
    assert replay(log, out) == 4
    rows = read_rrd(out)
    assert column(rows, "/errors/position_mm", SCALARS) == [(0.05, [pytest.approx(12.0)])]
    assert sim_seconds(rows["/harvest/log"][-1]) == pytest.approx(0.1)
    assert rows["/harvest/log"][-1]["TextLog:level"] == ["ERROR"]
    assert rows["/world/berries"][-1]["Points3D:labels"] == ["tag 12"]
    assert rows["/world/estimate/berry"][-1]["Points3D:labels"] == ["tag 12 (eye_to_hand)"]


@pytest.mark.parametrize(
    ("record", "error", "match"),
    [
        ({"kind": "step", "t": 0.0, "q": [0.01, 0.02]}, ShapeError, "record 1: q must be 9"),
        ({"kind": "step", "t": "soon"}, InputError, "record 1: t must be a finite number"),
        ({"kind": "step", "t": 0.0, "pose": [[1, 0], [0, 1]]}, ShapeError, "record 1: pose"),
        ({"t": 0.0}, InputError, "record 1: a record must be an object with a string 'kind'"),
    ],
)
def test_malformed_record_is_a_typed_error_naming_it(tmp_path, record, error, match) -> None:
    log = tmp_path / "bad.jsonl"
    _write(log, [record])
    with pytest.raises(error, match=match):
        replay(log, tmp_path / "bad.rrd")


def test_a_line_that_is_not_json_is_named(tmp_path, capsys) -> None:
    log = tmp_path / "bad.jsonl"
    log.write_text('{"kind": "ripeness", "value": 1.0}\nnot json\n{"kind": "x"}\n')
    assert main(["replay", str(log), "--record", str(tmp_path / "o.rrd")]) == 2
    assert "line 2 is not a JSON record" in capsys.readouterr().err


def test_view_without_a_display_fails_before_the_run(tmp_path, monkeypatch, capsys) -> None:
    import sys

    if not sys.platform.startswith("linux"):
        pytest.skip("the display check is Linux's")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    log = tmp_path / "run.jsonl"
    _write(log, [{"kind": "ripeness", "value": 1.0}])
    assert main(["replay", str(log)]) == 2
    assert "--record run.rrd" in capsys.readouterr().err


def test_a_viewer_that_cannot_start_is_one_line(tmp_path, monkeypatch) -> None:
    import rerun as rr

    from softarm.viz.rerun_sdk import ViewerUnavailableError, open_recording

    def refuse(**kwargs):
        assert kwargs["connect"] is False and kwargs["executable_path"] == "/opt/bin/rerun"
        raise RuntimeError("Failed to find Rerun Viewer executable in PATH.\n\n  details")

    monkeypatch.setenv("DISPLAY", ":0")
    monkeypatch.setattr(rr, "spawn", refuse)
    monkeypatch.setattr("softarm.viz.rerun_sdk.shutil.which", lambda name: "/opt/bin/rerun")
    with pytest.raises(ViewerUnavailableError, match=r"viewer: Failed to find Rerun Viewer[^\n]*$"):
        open_recording("x", tmp_path / "x.rrd", spawn=True)


@pytest.mark.slow
def test_the_viewer_loads_the_recording_and_its_layout(harvest_run) -> None:
    """The rerun executable the wheel installs verifies the file as the viewer loads it;
    the default layout (blueprint) travels in the file."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    from rerun.chunk import RrdReader

    _, rrd = harvest_run
    assert RrdReader(rrd).blueprints()
    beside = Path(sys.executable).with_name("rerun")
    exe = shutil.which("rerun") or (str(beside) if beside.exists() else None)
    if exe is None:
        pytest.skip("the rerun executable is not installed")
    done = subprocess.run(
        [exe, "rrd", "verify", str(rrd)], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]


@pytest.mark.slow
def test_replay_draws_the_runs_bush_and_refuses_another(harvest_run, tmp_path, capsys) -> None:
    log, _ = harvest_run
    out = tmp_path / "scene.rrd"
    assert (
        main(["replay", str(log), "--record", str(out), "--sim-seed", "0", "--berries", "1"]) == 0
    )
    rows = read_rrd(out)
    assert "/world/canes" in rows
    (bush,) = rows["/world/bush/berries"]
    assert bush["Points3D:labels"] == ["tag 10"]
    other = ["replay", str(log), "--record", str(out), "--sim-seed", "3", "--berries", "1"]
    assert main(other) == 2
    assert "tag 10 is not a berry of the simulated bush of seed 3" in capsys.readouterr().err


@pytest.mark.slow
def test_a_viewer_closed_before_the_end_does_not_fail_the_run(tmp_path, caplog) -> None:
    """The recording streams to a viewer that is gone (nothing listens on its port) and
    to a file: closing warns, and the file is complete."""
    import socket

    import rerun as rr

    from softarm.viz.rerun_sdk import close_recording

    with socket.socket() as s:  # a free port: no viewer there
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    stream = rr.RecordingStream("softarm", recording_id="gone")
    out = tmp_path / "both.rrd"
    stream.set_sinks(rr.GrpcSink(f"rerun+http://127.0.0.1:{port}/proxy"), rr.FileSink(str(out)))
    for i in range(3):
        stream.set_time("sim_time", duration=0.1 * i)
        stream.log("errors/x", rr.Scalars(float(i)))
    close_recording(stream, viewer=True)
    assert "viewer went away" in caplog.text
    assert [v for _, v in column(read_rrd(out), "/errors/x", SCALARS)] == [[0.0], [1.0], [2.0]]
