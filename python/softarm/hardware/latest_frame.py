"""The newest frame of a camera, not the oldest one its driver has queued.

A V4L2 (UVC) camera fills a ring of a few buffers and ``VideoCapture.read`` hands back
the oldest one waiting. A loop that reads slower than the camera delivers (a 20 Hz
control loop on a 30 fps camera), or that stops reading for a while (the harvest reads
C2 only where it needs the berry fix), then sees the world as it was one to several
frames ago: a berry fix from a frame taken before the arm's last move, joined to the
cube's pose of now. ``CAP_PROP_BUFFERSIZE`` is honoured by some backends only, and even
one buffer holds the frame taken just after the last read. So a thread reads the device
as fast as it delivers and keeps only the newest frame; :meth:`LatestFrame.read` hands
that out, each frame once.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.checks import finite_real
from softarm.errors import HardwareError, ParameterError
from softarm.hardware.protocols import Camera

__all__ = ["LatestFrame", "is_live", "newest_frames"]

Image = npt.NDArray[np.uint8]

#: How long :meth:`LatestFrame.read` waits for a frame newer than the last one it gave
#: (s): six frame intervals at 30 fps. A camera that delivers nothing for that long has
#: dropped the frame (``None``, as :class:`~softarm.hardware.protocols.Camera` says).
WAIT_S = 0.2

#: The fastest the thread reads the device (Hz). A camera's read blocks until its next
#: frame (the ZED2's fastest mode is 100 fps); a source that never blocks (a fake, a
#: device in error returning at once) is not spun on faster than this.
MAX_READ_HZ = 240.0

#: How long :meth:`LatestFrame.close` waits for the thread to leave the device's read
#: (s): a live camera's read ends within a frame interval.
CLOSE_WAIT_S = 1.0


class LatestFrame:
    """A :class:`~softarm.hardware.protocols.Camera` giving ``camera``'s newest frame.

    Args:
        camera: the device, read only by this object's thread from now on.
        wait_s: how long :meth:`read` waits for a frame it has not given yet.

    Raises:
        ParameterError: ``wait_s`` is not a positive finite number of seconds.
    """

    def __init__(self, camera: Camera, wait_s: float = WAIT_S) -> None:
        if not (finite_real(wait_s) and wait_s > 0):
            raise ParameterError(f"wait_s must be a positive finite time (s), got {wait_s!r}")
        self.camera, self.wait_s = camera, float(wait_s)
        self._new = threading.Condition()
        self._frame: Image | None = None
        self._count = 0  # frames delivered by the device
        self._given = 0  # the count of the last frame handed out
        self._failure: BaseException | None = None
        self._closed = False
        self._thread = threading.Thread(target=self._grab, name="softarm-camera", daemon=True)
        self._thread.start()

    def read(self) -> Image | None:
        """The newest frame not handed out before, waiting up to ``wait_s`` for one;
        ``None`` when none came (a dropped frame).

        Raises:
            HardwareError: the camera is closed, or its reading thread failed (the
                device's own error, chained).
        """
        with self._new:
            self._new.wait_for(self._ready, timeout=self.wait_s)
            if self._closed:
                raise HardwareError("camera is closed")
            if self._failure is not None:
                raise HardwareError(f"camera failed: {self._failure}") from self._failure
            if self._count == self._given:
                return None
            self._given = self._count
            return self._frame

    def close(self) -> None:
        """Stop the thread, then close the device. Calling it twice is harmless."""
        with self._new:
            if self._closed:
                return
            self._closed = True
            self._new.notify_all()
        # The device is released only once its reader is out of ``read``: OpenCV's
        # release during another thread's read can crash some backends. A device stuck
        # in its read (unplugged mid-frame) is left open to the process's exit.
        self._thread.join(timeout=CLOSE_WAIT_S)
        if not self._thread.is_alive():
            self.camera.close()

    def _ready(self) -> bool:
        return self._closed or self._failure is not None or self._count > self._given

    def _grab(self) -> None:
        """The device read as fast as it delivers; a dropped frame is skipped."""
        while True:
            started = time.monotonic()
            try:
                frame: Any = self.camera.read()
            except Exception as exc:  # handed to the reader, who raises it
                with self._new:
                    if not self._closed:
                        self._failure = exc
                    self._new.notify_all()
                return
            with self._new:
                if self._closed:
                    return
                if frame is not None:
                    self._frame, self._count = frame, self._count + 1
                    self._new.notify_all()
                rest = 1.0 / MAX_READ_HZ - (time.monotonic() - started)
                if rest > 0:  # woken early by close()
                    self._new.wait(rest)


def is_live(source: Any) -> bool:
    """Whether an OpenCV ``source`` is a live camera (a device index, a ``/dev`` node, a
    stream URL) rather than a recorded video file, whose frames are all wanted in order."""
    if isinstance(source, int) and not isinstance(source, bool):
        return True
    return isinstance(source, str) and (source.startswith("/dev/") or "://" in source)


def newest_frames(camera: Camera, source: Any) -> Camera:
    """``camera`` (opened on ``source``) read through :class:`LatestFrame` where the
    source is live (:func:`is_live`), as it is otherwise."""
    return LatestFrame(camera) if is_live(source) else camera
