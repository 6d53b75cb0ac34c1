"""``replay --bag`` hardened (issue 42, items 7, 12 and 19): a log that ``--log``
appended to holds several runs, and one is picked (never collapsed into one message);
header and step values a bag cannot hold, and cameras of the wrong type, are one line
each; a stop removes the half-written bag and its temporary folder. The logs are
written here; nothing is simulated."""

from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rosbags")

from bag_stops import sigterm_while_writing_bag
from softarm.cli import main
from softarm.commands import replay
from softarm.harvest.records.header import split_runs
from softarm.harvest.records.log import CUT_MARK
from viz.test_bag import _read

NS = 1_000_000_000
Q = [0.0] * 9


def _step(t: float, state: str = "servo") -> dict[str, Any]:
    return {"kind": "step", "t": t, "q": Q, "state": state}


def _header(start_ns: int = 1_000 * NS, **fields: Any) -> dict[str, Any]:
    return {"kind": "header", "format": 2, "started_unix_ns": start_ns, **fields}


def _log(path: Path, records: list[dict[str, Any]]) -> Path:
    path.write_text("".join(json.dumps(r) + "\n" for r in records))
    return path


def _two_runs(path: Path) -> Path:
    first = [_header(1_000 * NS), _step(0.0), _step(0.1), _step(0.2)]
    second = [_header(2_000 * NS), _step(0.0, "idle"), _step(0.1, "idle")]
    return _log(path, first + second)


def _states(bag: Path) -> list[tuple[int, str]]:
    return [(ns, msg.data) for ns, msg in _read(bag)["/harvest/state"]]


def test_a_log_of_two_runs_needs_one_picked(tmp_path: Path, capsys) -> None:
    """Item 7: the second run's clock restarts at 0, and its steps collapsed into one
    message of the first run's last time, exit 0."""
    log = _two_runs(tmp_path / "run.jsonl")
    bag = tmp_path / "run.mcap"
    assert main(["replay", str(log), "--bag", str(bag)]) == 2
    err = capsys.readouterr().err.strip()
    assert "holds 2 runs" in err and "--run" in err and "\n" not in err
    assert not bag.exists()


def test_each_run_of_a_log_makes_its_own_bag(tmp_path: Path) -> None:
    log = _two_runs(tmp_path / "run.jsonl")
    first, second = tmp_path / "1.mcap", tmp_path / "2.mcap"
    assert main(["replay", str(log), "--bag", str(first), "--run", "1"]) == 0
    assert main(["replay", str(log), "--bag", str(second), "--run", "2"]) == 0
    assert [ns for ns, _ in _states(first)] == [1_000 * NS + round(t * NS) for t in (0, 0.1, 0.2)]
    assert _states(second) == [(2_000 * NS, "idle"), (2_000 * NS + NS // 10, "idle")]


def test_a_run_the_log_does_not_hold_is_refused(tmp_path: Path, capsys) -> None:
    log = _two_runs(tmp_path / "run.jsonl")
    assert main(["replay", str(log), "--bag", str(tmp_path / "b.mcap"), "--run", "3"]) == 2
    assert "--run 3: the log holds 2 run(s)" in capsys.readouterr().err
    assert main(["replay", str(log), "--run", "1"]) == 2
    assert "--run: picks the run" in capsys.readouterr().err


def test_runs_split_at_headers() -> None:
    older = [_step(0.0)]
    assert split_runs([]) == [[]]
    assert split_runs(older) == [older]
    assert len(split_runs([*older, _header(), _step(0.0)])) == 2  # a headerless run first
    cut = [{"kind": CUT_MARK}, _header(), _step(0.0)]
    assert split_runs(cut) == [cut[1:]]  # the mark of a cut line is not a run


@pytest.mark.parametrize(
    ("records", "named"),
    [
        # Item 12: a start past what a ROS 2 stamp holds (struct.error).
        ([_header(2**63 - 1), _step(0.0)], "started_unix_ns must be an integer of ns"),
        ([_header(2**31 * NS), _step(0.0)], "started_unix_ns must be an integer of ns"),
        ([_header(-1), _step(0.0)], "started_unix_ns must be an integer of ns"),
        # Item 12: a step time whose stamp overflows (OverflowError).
        ([_header(), _step(0.0), _step(1e300)], "record 3: t = 1e+300 s"),
        ([_header(), _step(0.0), _step(2.2e9)], "record 3: t = 2200000000.0 s"),
        # Item 12: cameras of the wrong type.
        ([_header(cameras={"camera_c1": 5}), _step(0.0)], "cameras.camera_c1 must hold"),
        ([_header(cameras={"c1": {}}), _step(0.0)], "header cameras.c1: the cameras are"),
        ([_header(cameras=[1]), _step(0.0)], "header cameras must be an object"),
        (
            [_header(cameras={"camera_c1": {"width": "640", "height": 480, "K": [1] * 9}})],
            "width and height must be integers",
        ),
        (
            [_header(cameras={"camera_c2": {"width": 64, "height": 48, "K": [1, 2]}})],
            "cameras.camera_c2.K must be 9 numbers",
        ),
        (
            [_header(cameras={"camera_c2": {"width": 64, "height": 48, "K": "x" * 9}})],
            "cameras.camera_c2.K must be numbers",
        ),
        ([_header(grasp_offset_m="x"), _step(0.0)], "grasp_offset_m"),
        ([_header(pressure_map=[1]), _step(0.0)], "pressure_map must be an object"),
    ],
)
def test_values_a_bag_cannot_hold_are_one_line(
    tmp_path: Path, capsys, records: list[dict[str, Any]], named: str
) -> None:
    log = _log(tmp_path / "run.jsonl", records)
    bag = tmp_path / "run.mcap"
    assert main(["replay", str(log), "--bag", str(bag)]) == 2
    err = capsys.readouterr().err.strip()
    assert named in err and "\n" not in err and "Traceback" not in err
    assert not bag.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["run.jsonl"]


def test_a_valid_camera_in_the_header_reaches_the_bag(tmp_path: Path) -> None:
    camera = {"width": 64, "height": 48, "K": [[50, 0, 31.5], [0, 50, 23.5], [0, 0, 1]],
              "D": [0.1, 0, 0, 0, 0]}  # fmt: skip
    log = _log(tmp_path / "run.jsonl", [_header(cameras={"camera_c2": camera}), _step(0.0)])
    assert main(["replay", str(log), "--bag", str(tmp_path / "run.mcap")]) == 0
    (_, info), = _read(tmp_path / "run.mcap")["/camera_c2/camera_info"]  # fmt: skip
    assert (info.width, info.height) == (64, 48) and info.d[0] == pytest.approx(0.1)


def test_a_frame_time_a_bag_cannot_hold_names_the_frame(tmp_path: Path, capsys) -> None:
    from viz.test_bag_map_frames import _frames

    _frames(tmp_path / "frames")
    index = json.loads((tmp_path / "frames" / "frames.json").read_text())
    index["frames"][4]["t"] = 1e300  # the C1 window, the only c1 frame
    (tmp_path / "frames" / "frames.json").write_text(json.dumps(index))
    log = _log(tmp_path / "run.jsonl", [_step(0.0)])
    argv = [
        "replay",
        str(log),
        "--bag",
        str(tmp_path / "b.mcap"),
        "--frames",
        str(tmp_path / "frames"),
    ]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "c1 frame 0" in err and "1e+300" in err and "\n" not in err


def test_replay_stopped_by_sigterm_leaves_no_temporary_files(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    """Item 19: SIGTERM ended replay where it stood, leaving a ``.bag-*/`` folder and a
    ``.*.tmp.mcap`` per kill; now it unwinds through their clean-up, exit 143."""
    log = _log(tmp_path / "run.jsonl", [_step(0.1 * i) for i in range(5)])
    sigterm_while_writing_bag(monkeypatch, after=5)
    previous = signal.signal(signal.SIGTERM, lambda s, f: pytest.fail("no handler"))
    try:
        status = main(["replay", str(log), "--bag", str(tmp_path / "run.mcap")])
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert status == 143
    assert "softarm replay: interrupted by SIGTERM" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.jsonl"]
    assert getattr(replay.run, "__wrapped__", None) is not None  # the shared handling
