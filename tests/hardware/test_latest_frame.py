"""A live camera read through :class:`LatestFrame` gives its newest frame, each once: not
the oldest one its driver queued while the control loop was not reading."""

from __future__ import annotations

import queue
import threading
import time

import numpy as np
import pytest

from softarm.errors import HardwareError, ParameterError
from softarm.hardware import latest_frame
from softarm.hardware.latest_frame import MAX_READ_HZ, LatestFrame, is_live, newest_frames
from softarm.hardware.protocols import Camera


class QueuedDevice:
    """A camera whose driver queues frames (as V4L2's ring of buffers does): ``read``
    waits for the next frame and hands out the oldest waiting; after 20 ms with none it
    reports a dropped frame. Released while a read is under way, it records it."""

    def __init__(self) -> None:
        self.frames: queue.Queue[np.ndarray | Exception] = queue.Queue()
        self.reads = 0
        self.closed = False
        self.inside = False
        self.released_while_reading = False

    def deliver(self, *numbers: int) -> None:
        for n in numbers:
            self.frames.put(np.full((2, 3, 3), n, np.uint8))

    def read(self) -> np.ndarray | None:
        self.reads += 1
        self.inside = True
        try:
            item = self.frames.get(timeout=0.02)
        except queue.Empty:
            return None
        finally:
            self.inside = False
        if isinstance(item, Exception):
            raise item
        return item

    def close(self) -> None:
        self.released_while_reading |= self.inside
        self.closed = True


def _entered(device: QueuedDevice, reads: int) -> None:
    """Wait until the reader thread is inside its ``reads``-th read: every frame before
    is stored."""
    deadline = time.monotonic() + 5.0
    while device.reads < reads:
        assert time.monotonic() < deadline, "the reader thread never read"
        time.sleep(0.001)


def test_the_newest_frame_not_the_oldest_queued() -> None:
    device = QueuedDevice()
    device.deliver(1, 2, 3)  # three frames while the loop was not reading
    cam = LatestFrame(device)
    try:
        assert isinstance(cam, Camera)
        _entered(device, 4)
        frame = cam.read()
        assert frame is not None and int(frame[0, 0, 0]) == 3
        device.deliver(4)
        frame = cam.read()
        assert frame is not None and int(frame[0, 0, 0]) == 4
    finally:
        cam.close()


def test_each_frame_once_then_none_after_the_wait() -> None:
    device = QueuedDevice()
    device.deliver(7)
    cam = LatestFrame(device, wait_s=0.05)
    try:
        _entered(device, 2)
        assert cam.read() is not None
        assert cam.read() is None  # nothing new came: a dropped frame, not frame 7 again
    finally:
        cam.close()


def test_a_device_error_is_a_hardware_error_naming_it() -> None:
    device = QueuedDevice()
    device.frames.put(OSError("unplugged"))
    cam = LatestFrame(device)
    with pytest.raises(HardwareError, match="unplugged") as raised:
        cam.read()
    assert isinstance(raised.value.__cause__, OSError)
    cam.close()


def test_close_stops_the_reader_before_releasing_the_device() -> None:
    device = QueuedDevice()
    cam = LatestFrame(device)
    _entered(device, 1)
    cam.close()
    assert device.closed and not device.released_while_reading
    cam.close()  # twice is harmless
    with pytest.raises(HardwareError, match="closed"):
        cam.read()


def test_a_device_stuck_in_its_read_is_not_released_under_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(latest_frame, "CLOSE_WAIT_S", 0.05)
    stuck, unstick = threading.Event(), threading.Event()

    class Stuck:
        closed = False

        def read(self) -> None:
            stuck.set()
            unstick.wait(5.0)

        def close(self) -> None:
            self.closed = True

    device = Stuck()
    cam = LatestFrame(device)
    stuck.wait(5.0)
    cam.close()
    assert not device.closed  # left to the process's exit, never released mid-read
    unstick.set()


def test_a_device_that_never_blocks_is_not_spun_on() -> None:
    class Instant:
        reads = 0

        def read(self) -> np.ndarray:
            self.reads += 1
            return np.zeros((1, 1, 3), np.uint8)

        def close(self) -> None:
            pass

    device = Instant()
    start = time.monotonic()
    cam = LatestFrame(device)
    time.sleep(0.1)
    cam.close()
    assert device.reads <= (time.monotonic() - start) * MAX_READ_HZ + 2


@pytest.mark.parametrize("wait", [0.0, -1.0, float("nan"), float("inf"), "0.2"])
def test_a_bad_wait_names_it(wait: object) -> None:
    with pytest.raises(ParameterError, match="wait_s"):
        LatestFrame(QueuedDevice(), wait_s=wait)  # type: ignore[arg-type]


def test_only_live_sources_are_read_for_their_newest_frame() -> None:
    assert is_live(0) and is_live("/dev/video2") and is_live("rtsp://cam/stream")
    assert not is_live("recorded.mp4") and not is_live(True)
    device = QueuedDevice()
    assert newest_frames(device, "recorded.mp4") is device  # every frame, in order
    live = newest_frames(device, 0)
    assert isinstance(live, LatestFrame)
    live.close()
