"""Recorded camera frames for the dry run of the hardware path (issue 24, item 3):
:class:`FrameRecorder` saves each frame the vision reads, with its time, as a lossless
PNG and an entry of ``frames.json``; :class:`FrameFolder` gives them back, in the order
they were read, checking that none is missing or out of order. Beside the frames the
index keeps named streams of other readings (the ripeness sensor's, the pressures
sent), in the order they were taken."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from softarm.errors import ConfigError
from softarm.files import write_text
from softarm.files.fresh import FreshFolder
from softarm.files.images import read_image, write_image
from softarm.files.read import load_json
from softarm.harvest.records.frame_index import (
    BERRY_STATES,
    RIPENESS,
    check_entry,
    check_streams,
)
from softarm.vision.crop import ImageCrop

__all__ = ["INDEX", "TIME_TOLERANCE_S", "FrameFolder", "FrameRecorder"]

#: The index of a frames folder: one entry per frame read, in the order read.
INDEX = "frames.json"

#: How far (s) a replayed frame's time may lie from its recorded time: both clocks step
#: by the same control periods, so only rounding separates them.
TIME_TOLERANCE_S = 1e-9

Frame = Callable[[float], Any]


def _cv2() -> Any:
    from softarm.hardware.camera import import_cv2

    return import_cv2()


class FrameRecorder:
    """Records the frames of the cameras it wraps into ``folder``: into a fresh folder
    beside it (:attr:`folder` while recording), moved into place by :meth:`save`, so
    that an earlier recording there is replaced whole or not at all; :meth:`discard`
    drops an unfinished one.

    Raises:
        OutputError: ``folder`` exists and holds other files than an earlier recording.
    """

    def __init__(self, folder: str | Path) -> None:
        self.target = Path(folder)
        self._fresh = FreshFolder(folder, "recording", INDEX)
        self.folder = self._fresh.path
        self.entries: list[dict[str, Any]] = []
        # The sensor's readings and the berries' outcomes are kept even when there are
        # none (a run whose one berry was unripe, never picked): its replay then reads
        # none, instead of finding the stream missing.
        self.streams: dict[str, list[Any]] = {RIPENESS: [], BERRY_STATES: []}

    def record(self, stream: str, value: Any) -> None:
        """Append ``value`` (JSON: numbers, lists, strings) to the named stream."""
        self.streams.setdefault(stream, []).append(value)

    def wrap(self, camera: str, frame: Frame) -> Frame:
        """``frame`` that records each image it gives as ``camera``'s."""

        def recorded(t: float) -> Any:
            image = frame(t)
            self._save(camera, t, image)
            return image

        return recorded

    def wrap_pair(
        self, read: Callable[[], tuple[Any, Any]], now: Callable[[], float]
    ) -> Callable[[], tuple[Any, Any]]:
        """The stereo source ``read`` that records each pair it gives, its eyes as
        ``c1_left`` and ``c1_right`` at the time ``now`` tells."""

        def recorded() -> tuple[Any, Any]:
            left, right = read()
            t = now()
            self._save("c1_left", t, left)
            self._save("c1_right", t, right)
            return left, right

        return recorded

    def _save(self, camera: str, t: float, image: Any) -> None:
        n = sum(e["camera"] == camera for e in self.entries)
        entry: dict[str, Any] = {"camera": camera, "n": n, "t": float(t), "file": None}
        if image is not None:
            entry["file"] = f"{camera}_{n:06d}.png"
            write_image(self.folder / entry["file"], np.asarray(image), "frame file")
            if (
                isinstance(image, ImageCrop)
                and image.origin is not None
                and image.full_size is not None
            ):
                entry["origin"], entry["full_size"] = list(image.origin), list(image.full_size)
        self.entries.append(entry)

    def save(self) -> Path:
        """Write the index and move the recording into place; the index's path."""
        index = {"frames": self.entries, "streams": self.streams}
        write_text(self.folder / INDEX, json.dumps(index, indent=1) + "\n", "frames index")
        self._fresh.commit()
        self.folder = self.target
        return self.folder / INDEX

    def discard(self) -> None:
        """Drop an unfinished recording (nothing once :meth:`save` moved it into place)."""
        self._fresh.discard()


class FrameFolder:
    """The frames of a folder :class:`FrameRecorder` wrote.

    Raises:
        ConfigError: the index is missing or broken, a frame file is missing, or a
            camera's frames are out of order (the file or entry named).
    """

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        data = load_json(self.folder / INDEX, "frames index")
        frames = data.get("frames") if isinstance(data, dict) else None
        if not isinstance(frames, list):
            raise ConfigError(f"{self.folder / INDEX}: frames must be a list of entries")
        # Every value the replay reads is checked here, before anything is replayed.
        self.streams = check_streams(str(self.folder / INDEX), data.get("streams", {}))
        self.entries: dict[str, list[dict[str, Any]]] = {}
        for i, entry in enumerate(frames):
            self._check(i, entry)
            self.entries.setdefault(entry["camera"], []).append(entry)

    def _check(self, i: int, entry: Any) -> None:
        where = f"{self.folder / INDEX}: frames[{i}]"
        check_entry(where, entry)
        earlier = self.entries.get(entry["camera"], [])
        if entry["n"] != len(earlier) or (earlier and entry["t"] < earlier[-1]["t"]):
            raise ConfigError(
                f"{where}: {entry['camera']} frame {entry['n']} at t = {entry['t']} is out "
                f"of order (expected frame {len(earlier)}, not before the last one's time)"
            )
        if entry["file"] is not None and not (self.folder / entry["file"]).is_file():
            raise ConfigError(
                f"{where}: frame file {str(self.folder / entry['file'])!r} is missing"
            )

    def stream(self, name: str) -> list[Any]:
        """The readings of stream ``name``, in the order taken.

        Raises:
            ConfigError: the recording has no such stream.
        """
        if name not in self.streams or not isinstance(self.streams[name], list):
            raise ConfigError(f"{self.folder / INDEX}: no {name!r} readings recorded")
        return self.streams[name]

    def frame(self, camera: str) -> Frame:
        """``camera``'s frames, one per call in the order recorded; each must be asked
        for at the time it was recorded (within :data:`TIME_TOLERANCE_S`), or the
        replay has left the recording.

        Raises:
            ConfigError: more frames are read than were recorded, or one is read at
                another time than it was recorded.
        """
        entries = iter(self.entries.get(camera, []))

        def replayed(t: float) -> Any:
            entry = next(entries, None)
            if entry is None:
                raise ConfigError(f"{self.folder}: no {camera} frame left to replay at t = {t}")
            if not abs(t - entry["t"]) <= TIME_TOLERANCE_S:  # a NaN time is not close
                raise ConfigError(
                    f"{self.folder}: the replay left the recording: {camera} frame "
                    f"{entry['n']} asked for at t = {t!r} s, recorded at {entry['t']!r} s"
                )
            return None if entry["file"] is None else self._image(entry)

        return replayed

    def pair(self, now: Callable[[], float]) -> Callable[[], tuple[Any, Any]]:
        """The recorded stereo source: one pair per call, asked for at the time ``now``
        tells (checked as :meth:`frame` checks it)."""
        left, right = self.frame("c1_left"), self.frame("c1_right")
        return lambda: (left(now()), right(now()))

    def _image(self, entry: dict[str, Any]) -> Any:
        image = read_image(self.folder / entry["file"], "frame file", error=ConfigError)
        if image is None:
            raise ConfigError(f"frame file {str(self.folder / entry['file'])!r} is not an image")
        if "origin" in entry:
            return ImageCrop(image, tuple(entry["origin"]), tuple(entry["full_size"]))
        return image
