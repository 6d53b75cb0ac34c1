"""The recorded frames of the dry run (issue 24, item 3): each frame read comes back
bit for bit, a crop with its window, in the order recorded; a folder with a missing or
out-of-order frame is a one-line error naming it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from softarm.errors import ConfigError
from softarm.harvest.records.frame_files import INDEX, FrameFolder, FrameRecorder
from softarm.vision.crop import ImageCrop


def _record(folder: Path) -> list[np.ndarray | None]:
    rng = np.random.default_rng(1)
    shown: list[np.ndarray | None] = [
        ImageCrop(rng.integers(0, 256, (8, 10, 3), np.uint8), (5, 7), (64, 48)),
        None,
        rng.integers(0, 256, (6, 4, 3), np.uint8),
    ]
    rec = FrameRecorder(folder)
    c1 = rec.wrap("c1", lambda t: shown[int(t)])
    for t in range(3):
        c1(float(t))
    rec.wrap("c2", lambda t: shown[2])(2.5)
    rec.save()
    return shown


def test_frames_come_back_bit_for_bit_in_order(tmp_path: Path) -> None:
    shown = _record(tmp_path)
    c1 = FrameFolder(tmp_path).frame("c1")
    first = c1(0.0)
    assert isinstance(first, ImageCrop) and first.origin == (5, 7) and first.full_size == (64, 48)
    assert shown[0] is not None and np.array_equal(first, shown[0])
    assert c1(1.0) is None
    assert shown[2] is not None and np.array_equal(c1(2.0), shown[2])
    with pytest.raises(ConfigError, match="no c1 frame left"):
        c1(3.0)


def test_a_missing_frame_file_is_named(tmp_path: Path) -> None:
    _record(tmp_path)
    (tmp_path / "c1_000002.png").unlink()
    with pytest.raises(ConfigError, match=r"c1_000002\.png") as err:
        FrameFolder(tmp_path)
    assert "\n" not in str(err.value)


def test_frames_out_of_order_are_refused(tmp_path: Path) -> None:
    _record(tmp_path)
    index = json.loads((tmp_path / INDEX).read_text())
    index["frames"][0], index["frames"][2] = index["frames"][2], index["frames"][0]
    (tmp_path / INDEX).write_text(json.dumps(index))
    with pytest.raises(ConfigError, match=r"frames\[0\]: c1 frame 2 .* out of order"):
        FrameFolder(tmp_path)


def test_a_run_that_read_no_ripeness_replays_none(tmp_path: Path) -> None:
    # A run that grasped nothing (its one berry unripe, never picked) read the sensor
    # never and ended no berry: its recording still holds both streams, empty, for the
    # replay to read.
    rec = FrameRecorder(tmp_path)
    rec.save()
    folder = FrameFolder(tmp_path)
    assert folder.stream("ripeness") == [] and folder.stream("berry_states") == []
