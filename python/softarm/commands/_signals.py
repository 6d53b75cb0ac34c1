"""SIGTERM and SIGINT as an exception, so that a run being stopped unwinds through its
``finally`` blocks (vent the arm, close the devices, sync the log) instead of dying
where it stands. Python's default SIGTERM action ends the process at once, with no
cleanup at all; SIGINT raises KeyboardInterrupt, which prints a traceback.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

__all__ = ["Interrupted", "raise_on_signals"]

#: Handled signals and the exit status a shell reports for them (128 + number).
SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupted(BaseException):
    """A stop request arrived. A BaseException like KeyboardInterrupt, so that the
    ``except Exception`` handlers of device code cannot swallow it."""

    def __init__(self, signum: int) -> None:
        self.signum = signum
        self.name = signal.Signals(signum).name
        super().__init__(f"interrupted by {self.name}")

    @property
    def exit_status(self) -> int:
        """128 + the signal number: 130 for SIGINT, 143 for SIGTERM."""
        return 128 + self.signum


def _raise(signum: int, frame: FrameType | None) -> None:
    # Ignore repeats while the first one is being handled: a second Ctrl-C must not cut
    # the venting short. SIGKILL still ends everything.
    for s in SIGNALS:
        signal.signal(s, signal.SIG_IGN)
    raise Interrupted(signum)


@contextmanager
def raise_on_signals() -> Iterator[None]:
    """Inside the block, SIGINT and SIGTERM raise :class:`Interrupted`; the previous
    handlers are restored on the way out. Only the main thread can install handlers, so
    elsewhere (a test runner's worker thread) the block runs unchanged."""
    try:
        previous = {s: signal.signal(s, _raise) for s in SIGNALS}
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
