"""The dry run of the hardware path: a simulated harvest of the rendered bush records
its frames, readings and commands with the rig's hw.toml; the hardware rig, fed that
recording through its device boundary, must send the same pressure commands and end
every berry the same way. A recording that does not match is reported as such."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from render_required import need_mujoco, unavailable
from softarm.cli import main
from softarm.config import load_config
from softarm.harvest.records.frame_files import INDEX
from softarm.vision.marker_body import SIMULATED_BODY

os.environ.setdefault("MUJOCO_GL", "egl")

#: A bush whose one ripe berry in reach is quick to pick (not a reported seed).
SEED = 902


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    need_mujoco()
    folder = tmp_path_factory.mktemp("dry") / "rec"
    args = [
        "harvest",
        "--sim",
        "--world",
        "bush",
        "--berries",
        "3",
        "--seed",
        str(SEED),
    ]
    log = folder.parent / "sim.jsonl"
    status = main([*args, "--record-frames", str(folder), "--log", str(log), "-q"])
    if not (folder / INDEX).is_file():
        unavailable("the rendered bush is unavailable here (EGL)")
    assert status == 0
    return folder


def _replay(folder: Path, tmp_path: Path) -> tuple[int, dict]:
    report = tmp_path / "replay.json"
    status = main(
        ["harvest", "--config", str(folder / "hw.toml"), "--frames", str(folder),
         "--dry-run", "--report", str(report), "--log", str(tmp_path / "replay.jsonl"), "-q"]
    )  # fmt: skip
    return status, json.loads(report.read_text())


def test_the_hardware_path_sends_the_recorded_commands(recording: Path, tmp_path: Path) -> None:
    status, report = _replay(recording, tmp_path)
    dry = report["dry_run"]
    assert status == 0 and dry["same"]
    assert dry["count"][0] == dry["count"][1] > 10
    assert dry["max_psi"] <= 1e-9 and dry["berries_as_recorded"]
    assert report["berries"] and report["berries"][0]["final_state"] == "done"
    logged = [
        json.loads(line)
        for line in (tmp_path / "replay.jsonl").read_text().splitlines()
        if '"pressure_command"' in line
    ]
    assert len(logged) >= dry["count"][0]  # and the close's vent
    records = [json.loads(line) for line in (tmp_path / "replay.jsonl").read_text().splitlines()]
    maps = [r for r in records if r["kind"] == "bush_map"]
    first = maps[0]  # the map after each look: what perception found
    assert first["berries"] and {"id", "position", "radius_m", "ripe"} <= set(first["berries"][0])
    assert all(len(c["coeffs"]) == 3 for c in first["canes"])
    # The hardware path flew the survey (on by default in both) the simulator
    # recorded, and refit the canes.
    done = [r for r in records if r["kind"] == "survey_done"]
    assert len(done) == 1 and done[0]["used"] >= 1


def _run_events(path: Path) -> list[tuple[object, ...]]:
    """The state machine's story of a run's log: each transition, each berry's result
    and the run's end, without times."""
    records = [json.loads(line) for line in path.read_text().splitlines()]
    story: list[tuple[object, ...]] = []
    for r in records:
        if r["kind"] == "transition":
            story.append(("transition", r["berry"], r["old"], r["new"]))
        elif r["kind"] == "berry_result":
            story.append(("berry_result", r["tag_id"], r["final_state"], r["fault"]))
        elif r["kind"] in ("run_done", "run_stopped"):
            story.append((r["kind"],))
    return story


def test_the_rig_files_name_the_body_the_recording_tracked(recording: Path) -> None:
    # The hardware's default body is the cube: a recording of another body must say so,
    # or its replay tracks the wrong tags' layout and leaves the recording.
    calibration = load_config(recording / "hw.toml").calibration
    assert SIMULATED_BODY != "cube"
    assert calibration.marker_body == SIMULATED_BODY and calibration.marker_length == 0.08


def test_both_rigs_run_the_recorded_harvest_by_one_policy(recording: Path, tmp_path: Path) -> None:
    """The simulator's run and the hardware rig's replay of it tell the same story:
    the same transitions, berry results and end of run (softarm.harvest.runs.policy)."""
    _replay(recording, tmp_path)
    sim = _run_events(recording.parent / "sim.jsonl")
    arm = _run_events(tmp_path / "replay.jsonl")
    assert sim[-1] == ("run_done",)
    assert arm == sim


def test_a_different_ripeness_reading_is_not_the_recording(recording: Path, tmp_path: Path) -> None:
    folder = tmp_path / "tampered"
    shutil.copytree(recording, folder)
    index = json.loads((folder / INDEX).read_text())
    index["streams"]["ripeness"] = [0.0 for _ in index["streams"]["ripeness"]]
    (folder / INDEX).write_text(json.dumps(index))
    status, report = _replay(folder, tmp_path)
    assert status == 1 and not report["dry_run"]["same"]


def test_a_missing_frame_is_a_one_line_error(
    recording: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "holed"
    shutil.copytree(recording, folder)
    (folder / "c2_000003.png").unlink()
    status = main(
        ["harvest", "--config", str(folder / "hw.toml"), "--frames", str(folder), "--dry-run"]
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "c2_000003.png" in err[0] and "missing" in err[0]


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["--config", "hw.toml", "--dry-run"], "--frames"),
        (["--config", "hw.toml", "--frames", "x"], "--dry-run"),
        (["--sim", "--record-frames", "x"], "--world bush"),
        (["--sim", "--survey"], "--survey"),
        (["--sim", "--no-survey"], "--survey"),
        (["--config", "hw.toml", "--survey"], "[perception] survey"),
    ],
)
def test_options_outside_their_mode_are_refused(
    args: list[str], named: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "hw.toml").write_text("")
    os.chdir(tmp_path)
    assert main(["harvest", *args]) == 2
    assert named in capsys.readouterr().err


def test_the_dry_runs_bag_carries_the_frames_it_replayed(recording: Path, tmp_path: Path) -> None:
    pytest.importorskip("rosbags")
    from rosbags.highlevel import AnyReader

    bag = tmp_path / "dry.mcap"
    argv = ["harvest", "--config", str(recording / "hw.toml"), "--frames", str(recording)]
    assert main([*argv, "--dry-run", "--bag", str(bag), "-q"]) == 0
    with AnyReader([bag]) as reader:
        topics = {c.topic for c in reader.connections}
    assert "/camera_c2/image/compressed" in topics and "/harvest/markers" in topics
