"""Recorded camera frames for the dry run of the hardware path (issue 24, item 3):
:class:`FrameRecorder` saves each frame the vision reads, with its time, as a lossless
PNG and an entry of ``frames.json``; :class:`FrameFolder` gives them back, in the order
they were read, checking that none is missing or out of order."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from softarm.errors import ConfigError
from softarm.files import write_text
from softarm.files.read import load_json
from softarm.vision.crop import ImageCrop

__all__ = ["INDEX", "FrameFolder", "FrameRecorder"]

#: The index of a frames folder: one entry per frame read, in the order read.
INDEX = "frames.json"

Frame = Callable[[float], Any]


def _cv2() -> Any:
    from softarm.hardware.camera import import_cv2

    return import_cv2()


class FrameRecorder:
    """Records the frames of the cameras it wraps into ``folder``."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.entries: list[dict[str, Any]] = []

    def wrap(self, camera: str, frame: Frame) -> Frame:
        """``frame`` that records each image it gives as ``camera``'s."""

        def recorded(t: float) -> Any:
            image = frame(t)
            self._save(camera, t, image)
            return image

        return recorded

    def _save(self, camera: str, t: float, image: Any) -> None:
        n = sum(e["camera"] == camera for e in self.entries)
        entry: dict[str, Any] = {"camera": camera, "n": n, "t": float(t), "file": None}
        if image is not None:
            entry["file"] = f"{camera}_{n:06d}.png"
            _cv2().imwrite(str(self.folder / entry["file"]), np.asarray(image))
            if (
                isinstance(image, ImageCrop)
                and image.origin is not None
                and image.full_size is not None
            ):
                entry["origin"], entry["full_size"] = list(image.origin), list(image.full_size)
        self.entries.append(entry)

    def save(self) -> Path:
        """Write the index; its path."""
        path = self.folder / INDEX
        write_text(path, json.dumps({"frames": self.entries}, indent=1) + "\n", "frames index")
        return path


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
        self.entries: dict[str, list[dict[str, Any]]] = {}
        for i, entry in enumerate(frames):
            self._check(i, entry)
            self.entries.setdefault(entry["camera"], []).append(entry)

    def _check(self, i: int, entry: Any) -> None:
        where = f"{self.folder / INDEX}: frames[{i}]"
        if not isinstance(entry, dict) or not {"camera", "n", "t", "file"} <= set(entry):
            raise ConfigError(f"{where} must have camera, n, t and file")
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

    def frame(self, camera: str) -> Frame:
        """``camera``'s frames, one per call in the order recorded (the time asked for
        is not used: the replay reads them as the recording did).

        Raises:
            ConfigError: more frames are read than were recorded.
        """
        entries = iter(self.entries.get(camera, []))

        def replayed(t: float) -> Any:
            entry = next(entries, None)
            if entry is None:
                raise ConfigError(f"{self.folder}: no {camera} frame left to replay at t = {t}")
            return None if entry["file"] is None else self._image(entry)

        return replayed

    def _image(self, entry: dict[str, Any]) -> Any:
        image = _cv2().imread(str(self.folder / entry["file"]), -1)  # IMREAD_UNCHANGED
        if image is None:
            raise ConfigError(f"frame file {str(self.folder / entry['file'])!r} is not an image")
        if "origin" in entry:
            return ImageCrop(image, tuple(entry["origin"]), tuple(entry["full_size"]))
        return image
