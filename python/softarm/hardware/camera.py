"""OpenCV ``VideoCapture`` cameras (the eye-to-hand C1 and the eye-in-hand C2).

``cv2`` is imported when a camera is opened, not when softarm is imported, so a broken
or missing OpenCV only affects code that actually uses a camera.
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.errors import HardwareError, HardwareUnavailableError, InputError

__all__ = ["MAX_DEVICE_INDEX", "OpenCVCamera", "import_cv2", "source_problem"]

Image = npt.NDArray[np.uint8]

#: Largest OpenCV device index: from 100 on, OpenCV reads the hundreds as a backend
#: (``200 + k`` is V4L2 device k). -1 ("any camera") crashes some drivers.
MAX_DEVICE_INDEX = 99


def source_problem(source: Any) -> str | None:
    """Why ``source`` cannot be an OpenCV video source, or None: a device index in
    [0, :data:`MAX_DEVICE_INDEX`], or a non-empty path/URL string that is UTF-8 (OpenCV
    takes it as a C string: a name that is not, or holds a NUL, crashes or truncates)."""
    if isinstance(source, bool) or not isinstance(source, int | str):
        return "must be a device index or a path/URL string"
    if isinstance(source, int):
        ok = 0 <= source <= MAX_DEVICE_INDEX
        return None if ok else f"must be a device index in [0, {MAX_DEVICE_INDEX}]"
    try:
        source.encode("utf-8")
    except UnicodeEncodeError:
        return "must be a UTF-8 path/URL string (OpenCV cannot open other names)"
    return None if source and "\0" not in source else "must be a non-empty path/URL string"


def import_cv2() -> ModuleType:
    """Import OpenCV or raise :class:`HardwareUnavailableError` saying how to get it."""
    try:
        return importlib.import_module("cv2")
    except ImportError as exc:
        raise HardwareUnavailableError(
            "cameras need OpenCV ('cv2'), which cannot be imported: "
            "pip install 'opencv-python-headless>=5.0,<5.1'"
        ) from exc


def _quietly_open(cv2: ModuleType, source: int | str) -> Any:
    """``cv2.VideoCapture(source)`` without OpenCV's own log lines (``[ WARN:0@0.012]
    global cap_v4l.cpp ... can't open camera by index``, one per backend tried): a
    device that cannot be opened is one :class:`HardwareUnavailableError` line instead."""
    log = getattr(getattr(cv2, "utils", None), "logging", None)
    if log is None:  # an OpenCV built without its logging module
        return cv2.VideoCapture(source)
    level = log.getLogLevel()
    log.setLogLevel(log.LOG_LEVEL_SILENT)
    try:
        return cv2.VideoCapture(source)
    finally:
        log.setLogLevel(level)


class OpenCVCamera:
    """A :class:`~softarm.hardware.protocols.Camera` on ``cv2.VideoCapture``.

    Args:
        source: device index (``0``), device path or stream URL.
        width, height: requested frame size, or ``None`` for the driver's default.

    Raises:
        InputError: ``source`` is no video source (:func:`source_problem`).
        HardwareUnavailableError: OpenCV is missing or the device cannot be opened.
    """

    def __init__(
        self, source: int | str = 0, width: int | None = None, height: int | None = None
    ) -> None:
        problem = source_problem(source)
        if problem is not None:
            raise InputError(f"camera source {problem}, got {source!r}")
        cv2 = import_cv2()
        self.source = source
        try:
            self._cap: Any = _quietly_open(cv2, source)
        except cv2.error as exc:  # what the checks above cannot foresee
            why = " ".join(str(exc).split())[:200]
            raise HardwareUnavailableError(f"cannot open camera {source!r}: {why}") from None
        if not self._cap.isOpened():
            self._cap.release()
            self._cap = None
            raise HardwareUnavailableError(f"cannot open camera {source!r} with OpenCV")
        if width is not None:
            self._cap.set(cv2.CAP_PROP_FRAME_WIDTH, width)
        if height is not None:
            self._cap.set(cv2.CAP_PROP_FRAME_HEIGHT, height)

    def read(self) -> Image | None:
        """One BGR frame ``(h, w, 3)``, or ``None`` when the driver dropped it."""
        if self._cap is None:
            raise HardwareError(f"camera {self.source!r} is closed")
        ok, frame = self._cap.read()
        if not ok or frame is None or getattr(frame, "size", 0) == 0:
            return None
        return np.asarray(frame, dtype=np.uint8)

    def close(self) -> None:
        """Release the device. Calling it twice is harmless."""
        if self._cap is not None:
            self._cap.release()
            self._cap = None
