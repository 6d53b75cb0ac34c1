"""Recorded camera frames (a ``--record-frames`` folder, :mod:`softarm.harvest.records.frame_files`)
as ``sensor_msgs/CompressedImage`` messages, each stamped at its frame's time ``t``.

The frame files are put in the bag as they are (PNG as recorded, or JPEG), with the
``format`` compressed_image_transport writes (``bgr8; png compressed bgr8``): OpenCV
wrote them from BGR arrays, so a PNG decoder shows their true colours. C2's frames and
C1's whole left frames at the looks go on each camera's ``image/compressed`` topic, whose
``camera_info`` the log's steps give; C1's windows around the cube go on their own topic
with a ``CameraInfo`` each, the full frame's intrinsics and size with ``roi`` placing
the window in it (the ROS convention for a sub-window of a calibrated camera).
"""

from __future__ import annotations

import dataclasses
import heapq
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from softarm.errors import ConfigError, InputError
from softarm.harvest.records.frame_files import INDEX, FrameFolder
from softarm.viz.bag.convert import Message
from softarm.viz.bag.messages import Messages
from softarm.viz.bag.scene import RunScene, stamp_ns

__all__ = ["IMAGE_TOPICS", "STREAMS", "FrameImages", "image_format", "scaled_camera"]

IMAGE = "sensor_msgs/msg/CompressedImage"
#: Topic -> message type of the topics the recorded frames add.
IMAGE_TOPICS: dict[str, str] = {
    "/camera_c1/image/compressed": IMAGE,
    "/camera_c2/image/compressed": IMAGE,
    "/camera_c1/window/image/compressed": IMAGE,
    "/camera_c1/window/camera_info": "sensor_msgs/msg/CameraInfo",
}
#: Recorded camera -> (topic namespace, header camera and tf frame). C1's right eye
#: (``c1_right``) is left in the folder: the header has no frame for it.
STREAMS: dict[str, tuple[str, str]] = {
    "c1_left": ("/camera_c1", "camera_c1"),
    "c2": ("/camera_c2", "camera_c2"),
    "c1": ("/camera_c1/window", "camera_c1"),
}
#: The cameras whose whole frames the recording holds (their sizes set the intrinsics).
WHOLE = ("c1_left", "c2")

_PNG, _JPEG = b"\x89PNG\r\n\x1a\n", b"\xff\xd8"


class FrameImages:
    """The images of a frames folder for a run's bag.

    Raises:
        ConfigError: the folder's index is missing or broken, a frame file is missing or
            not a PNG or JPEG image, or an entry's time or window is malformed (one line
            naming the file or entry).
    """

    def __init__(self, m: Messages, folder: str | Path, scene: RunScene) -> None:
        self.m, self.frames = m, FrameFolder(folder)
        self.index = self.frames.folder / INDEX
        cameras = dict(scene.cameras)
        for camera in WHOLE:
            first = next((e for e in self.frames.entries.get(camera, []) if e["file"]), None)
            name = STREAMS[camera][1]
            if first is not None and name in cameras:
                height, width = self._decode(first)[0].shape[:2]
                cameras[name] = scaled_camera(cameras[name], width, height)
        #: The run's scene, its cameras' intrinsics those of the recorded frames (a
        #: frame rendered smaller than the header's camera, as the bush world's C2 is,
        #: gets the intrinsics scaled to its size).
        self.scene = dataclasses.replace(scene, cameras=cameras)

    def messages(self) -> Iterator[Any]:
        """Every image message (with the windows' CameraInfo), in the order of their
        stamps; each topic's stamps are the frames' times, which the folder keeps in
        order."""

        def stream(camera: str) -> Iterator[Message]:
            topic, frame = STREAMS[camera]
            for entry in self.frames.entries.get(camera, []):
                if entry["file"] is None:  # the camera gave no image then
                    continue
                ns = self._ns(entry)
                image, data = self._decode(entry)
                msg = self.m.compressed_image(ns, frame, image_format(image, data), data)
                if camera == "c1":
                    info = self._window_info(ns, entry, image, frame)
                    if info is not None:
                        yield Message(f"{topic}/camera_info", ns, info)
                yield Message(f"{topic}/image/compressed", ns, msg)

        yield from heapq.merge(*(stream(c) for c in STREAMS), key=lambda item: item.ns)

    def _ns(self, entry: Mapping[str, Any]) -> int:
        # The folder checked every t (finite); its stamp must still fit in the bag.
        try:
            return stamp_ns(self.scene.start_ns, entry["t"])
        except InputError as exc:
            where = f"{self.index}: {entry['camera']} frame {entry['n']}"
            raise ConfigError(f"{where}: {exc}") from None

    def _decode(self, entry: Mapping[str, Any]) -> tuple[np.ndarray, bytes]:
        """The frame's pixels (for its size and pixel format) and its file's bytes."""
        from softarm.files.images import decode_image, read_image_bytes

        path = self.frames.folder / str(entry["file"])
        data = read_image_bytes(path, "frame file", error=ConfigError)
        image = None
        if data.startswith((_PNG, _JPEG)):
            image = decode_image(data, f"frame file {str(path)!r}", error=ConfigError)
        if image is None:
            raise ConfigError(f"frame file {str(path)!r} is not a PNG or JPEG image")
        return image, data

    def _window_info(
        self, ns: int, entry: Mapping[str, Any], image: np.ndarray, frame: str
    ) -> Any | None:
        """The CameraInfo of a C1 window: the full frame's (``full_size``) intrinsics,
        ``roi`` the window (``origin`` and the image's size); None without the header's
        camera or the window's place."""
        camera = self.scene.cameras.get(frame)
        if camera is None or "origin" not in entry:
            return None
        where = f"{self.index}: c1 frame {entry['n']}"
        try:
            x0, y0 = (int(v) for v in entry["origin"])
            width, height = (int(v) for v in entry["full_size"])
        except (KeyError, TypeError, ValueError):
            raise ConfigError(f"{where}: origin and full_size must be two integers each") from None
        h, w = image.shape[:2]
        if x0 < 0 or y0 < 0 or x0 + w > width or y0 + h > height:
            raise ConfigError(
                f"{where}: the {w} x {h} window at ({x0}, {y0}) is not inside the "
                f"{width} x {height} frame"
            )
        full = scaled_camera(camera, width, height)
        return self.m.camera_info(ns, frame, full, roi=(x0, y0, w, h))


def image_format(image: np.ndarray, data: bytes) -> str:
    """The CompressedImage ``format`` of encoded ``data`` decoded to ``image`` (OpenCV's
    channel order), as compressed_image_transport writes it: ``bgr8; png compressed
    bgr8``, ``mono8; png compressed``, ``bgr8; jpeg compressed bgr8``."""
    codec = "png" if data.startswith(_PNG) else "jpeg"
    depth = 16 if image.dtype == np.uint16 else 8
    channels = 1 if image.ndim == 2 else image.shape[2]
    pixels = {1: "mono", 3: "bgr", 4: "bgra"}.get(channels, "bgr") + str(depth)
    if channels == 1:
        return f"{pixels}; {codec} compressed"
    return f"{pixels}; {codec} compressed {pixels}"


def scaled_camera(camera: Mapping[str, Any], width: int, height: int) -> dict[str, Any]:
    """A header camera (``width``, ``height``, ``K``, ``D``) for images of ``width`` x
    ``height``: the focal lengths and principal point scaled with the image (pixel
    centres kept: ``c' = (c + 0.5) s - 0.5``), the distortion unchanged. A camera of that
    size, or one without a size, is returned as it is, with the size set."""
    out = dict(camera)
    w0, h0 = int(camera.get("width", 0)), int(camera.get("height", 0))
    out["width"], out["height"] = int(width), int(height)
    if (w0, h0) == (width, height) or w0 <= 0 or h0 <= 0:
        return out
    k = np.asarray(camera["K"], dtype=np.float64).reshape(3, 3).copy()
    for row, s in ((0, width / w0), (1, height / h0)):
        k[row, :2] *= s
        k[row, 2] = (k[row, 2] + 0.5) * s - 0.5
    out["K"] = k
    return out
