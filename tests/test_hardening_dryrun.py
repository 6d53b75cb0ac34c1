"""The dry run's recording hardened (issue 42, items 1, 10, 16, 18 and 20): frames.json
is checked where it is read, before anything is replayed (NaN pressures and times,
values of the wrong type, files outside the folder); the comparison cannot call NaN
"the same"; the rig's close after a stop does not write into the closed log; and a
recording is written aside and moved into place whole. Nothing is rendered: the
recordings are small ones written here."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from softarm.errors import ConfigError, OutputError
from softarm.harvest.records.frame_files import INDEX, FrameFolder, FrameRecorder
from softarm.harvest.records.log import HarvestLog
from softarm.harvest.rigs.replay.devices import ReplayDevices, compare_commands

COMMANDS = [["set", 0.0, [1.0, 2.0]], ["set", 0.01, [1.5, 2.5]], ["vent", 0.02]]


def _record(folder: Path) -> Path:
    """A small recording: two C2 frames, a crop of C1, and the streams the dry run reads."""
    rng = np.random.default_rng(7)
    rec = FrameRecorder(folder)
    c2 = rec.wrap("c2", lambda t: rng.integers(0, 256, (4, 6, 3), np.uint8))
    c2(0.0)
    c2(0.5)
    for command in COMMANDS:
        rec.record("commands", command)
    rec.record("ripeness", 0.8)
    rec.record("seed", 3)
    rec.record("berry_states", ["done", None, True, False])
    return rec.save()


def _tamper(folder: Path, change: Any) -> None:
    index = json.loads((folder / INDEX).read_text())
    change(index)
    (folder / INDEX).write_text(json.dumps(index))


def _set(path: list[Any], value: Any) -> Any:
    def change(index: dict[str, Any]) -> None:
        *parents, last = path
        node: Any = index
        for key in parents:
            node = node[key]
        node[last] = value

    return change


@pytest.fixture
def recording(tmp_path: Path) -> Path:
    _record(tmp_path / "rec")
    return tmp_path / "rec"


def test_the_small_recording_reads_back(recording: Path) -> None:
    folder = FrameFolder(recording)
    assert folder.stream("commands") == COMMANDS
    assert ReplayDevices(folder).recorded_seed() == 3


@pytest.mark.parametrize(
    ("path", "value", "named"),
    [
        # Item 1: NaN pressures and times must not pass as "the same".
        (["streams", "commands", 0, 2], [float("nan"), 2.0], r"commands\[0\]"),
        (["streams", "commands", 1, 1], float("nan"), r"commands\[1\]"),
        (["frames", 0, "t"], float("nan"), r"frames\[0\]: t must be a finite number"),
        (["frames", 1, "t"], float("inf"), r"frames\[1\]: t must be a finite number"),
        # Item 10: the recorded values of the wrong type.
        (["frames", 0, "t"], "0.0", r"frames\[0\]: t must be"),
        (["frames", 0, "t"], None, r"frames\[0\]: t must be"),
        (["frames", 0, "t"], [0.0], r"frames\[0\]: t must be"),
        (["frames", 0, "t"], True, r"frames\[0\]: t must be"),
        (["frames", 0, "camera"], ["c2"], r"frames\[0\]: camera must be"),
        (["frames", 0, "n"], "0", r"frames\[0\]: n must be"),
        (["frames", 0, "file"], 5, r"frames\[0\]: file must be"),
        (["frames", 0, "origin"], "ab", r"frames\[0\]: a crop needs origin"),
        (["streams", "commands", 2], ["vent"], r"commands\[2\]"),
        (["streams", "commands", 0], ["set", 0.0, "12"], r"commands\[0\]"),
        (["streams", "commands", 0], "set", r"commands\[0\]"),
        (["streams", "ripeness", 0], "0.8", r"ripeness\[0\] must be a finite number"),
        (["streams", "ripeness", 0], float("nan"), r"ripeness\[0\] must be a finite number"),
        (["streams", "seed", 0], "3", r"seed\[0\] must be an integer"),
        (["streams", "seed", 0], -1, r"seed\[0\] must be an integer"),
        (["streams", "seed"], 3, r"streams must be a table of lists"),
        (["streams", "berry_states", 0], ["done", None, "yes", False], r"berry_states\[0\]"),
        # Item 20: a frame file outside the folder.
        (["frames", 0, "file"], "../outside.png", r"frames\[0\]: file must be"),
        (["frames", 0, "file"], "/etc/passwd", r"frames\[0\]: file must be"),
        (["frames", 0, "file"], "..", r"frames\[0\]: file must be"),
    ],
)
def test_a_bad_recorded_value_is_refused_before_the_replay(
    recording: Path, path: list[Any], value: Any, named: str
) -> None:
    _tamper(recording, _set(path, value))
    with pytest.raises(ConfigError, match=named) as err:
        FrameFolder(recording)
    assert "\n" not in str(err.value) and str(recording / INDEX) in str(err.value)


def test_a_crop_without_its_full_size_is_refused(recording: Path) -> None:
    _tamper(recording, _set(["frames", 0, "origin"], [1, 2]))
    with pytest.raises(ConfigError, match="full_size"):
        FrameFolder(recording)


def test_two_seeds_are_refused(recording: Path) -> None:
    _tamper(recording, _set(["streams", "seed"], [3, 4]))
    with pytest.raises(ConfigError, match="seed must hold one integer"):
        FrameFolder(recording)


def test_a_file_outside_the_folder_is_not_read_even_when_it_exists(
    tmp_path: Path, recording: Path
) -> None:
    (tmp_path / "outside.png").write_bytes((recording / "c2_000000.png").read_bytes())
    _tamper(recording, _set(["frames", 0, "file"], "../outside.png"))
    with pytest.raises(ConfigError, match="in the folder itself"):
        FrameFolder(recording)


def test_a_frame_asked_for_at_a_nan_time_has_left_the_recording(recording: Path) -> None:
    c2 = FrameFolder(recording).frame("c2")
    with pytest.raises(ConfigError, match="left the recording"):
        c2(float("nan"))


def test_nan_pressures_or_times_are_never_the_same() -> None:
    """Item 1 at the comparison: ``max(0.0, nan)`` is 0.0, which called NaN the same."""
    sent = [["set", 0.0, [1.0, 2.0]], ["vent", 0.02]]
    nan_psi = [["set", 0.0, [float("nan"), 2.0]], ["vent", 0.02]]
    assert compare_commands(sent, nan_psi)["max_psi"] == float("inf")
    assert compare_commands(nan_psi, sent)["max_psi"] == float("inf")
    nan_t = [["set", float("nan"), [1.0, 2.0]], ["vent", 0.02]]
    assert compare_commands(sent, nan_t)["max_t"] == float("inf")
    assert compare_commands(sent, sent) == {
        "count": (2, 2), "max_psi": 0.0, "max_t": 0.0, "first_mismatch": None,
    }  # fmt: skip


def test_the_close_after_a_stop_does_not_write_into_the_closed_log(
    recording: Path, tmp_path: Path
) -> None:
    """Item 16: the stop completes and closes the log; the rig's close then vents
    through the command tap, which wrote into the closed log ("could not vent: I/O
    operation on closed file", exit 2)."""
    from softarm.commands._dry_run import log_commands

    devices = ReplayDevices(FrameFolder(recording))
    log = HarvestLog(tmp_path / "run.jsonl")
    log_commands(devices, log)
    devices.sink(["set", 0.0, [1.0, 2.0]])
    log.event("interrupted", signal="SIGTERM")
    log.close()
    devices.sink(["vent", 0.1])  # the close's vent
    assert devices.commands == [["set", 0.0, [1.0, 2.0]], ["vent", 0.1]]
    kinds = [json.loads(line)["kind"] for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    assert kinds == ["pressure_command", "interrupted"]


def test_a_new_recording_replaces_an_old_one_whole(tmp_path: Path) -> None:
    """Item 18: recorded over an earlier recording, no old file is left beside the new."""
    folder = tmp_path / "rec"
    _record(folder)
    (folder / "hw.toml").write_text("# the old rig\n")
    (folder / "c1_000009.png").write_bytes(b"old")
    _record(folder)
    assert sorted(p.name for p in folder.iterdir()) == [
        "c2_000000.png", "c2_000001.png", INDEX,
    ]  # fmt: skip
    assert [p.name for p in tmp_path.iterdir()] == ["rec"]  # no fresh or old folder left


def test_an_unfinished_recording_leaves_the_old_one_as_it_was(tmp_path: Path) -> None:
    """Item 18: a recording stopped half-way (never saved) leaves the earlier one intact
    and nothing beside it."""
    folder = tmp_path / "rec"
    _record(folder)
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    rec = FrameRecorder(folder)
    rec.wrap("c1", lambda t: np.zeros((3, 3, 3), np.uint8))(0.0)
    rec.record("seed", 9)
    assert rec.folder != folder and rec.folder.parent == folder.parent  # written aside
    rec.discard()
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    assert [p.name for p in tmp_path.iterdir()] == ["rec"]


def test_a_folder_that_is_not_a_recording_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "notes"
    folder.mkdir()
    (folder / "mine.txt").write_text("keep me")
    with pytest.raises(OutputError, match="other files than an earlier recording"):
        FrameRecorder(folder)
    assert (folder / "mine.txt").read_text() == "keep me"
    assert [p.name for p in tmp_path.iterdir()] == ["notes"]


def test_the_working_directory_is_not_replaced(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Replacing the folder the process stands in would move it away under it."""
    folder = tmp_path / "rec"
    _record(folder)
    monkeypatch.chdir(folder)
    with pytest.raises(OutputError, match="holds the working directory"):
        FrameRecorder(".")
