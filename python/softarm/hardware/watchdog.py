"""A daemon thread that calls a check function at a fixed period until stopped.

The safety layer keeps the watchdog *logic* (has a command arrived recently?) in a
plain method so tests can drive it with a fake clock; this thread only makes sure the
check runs even when the controller has hung and calls nothing at all.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from softarm.hardware.limits import WATCHDOG_PERIOD_S

__all__ = ["WatchdogThread"]

_log = logging.getLogger(__name__)


class WatchdogThread:
    """Run ``check()`` every ``period_s`` seconds on a daemon thread.

    An exception raised by ``check`` is logged and the thread keeps running: a watchdog
    that dies on the first error protects nothing. For the same reason ``period_s`` is
    bounded (:data:`~softarm.hardware.limits.WATCHDOG_PERIOD_S`): an overflowing period
    would raise inside ``Event.wait`` (outside the ``try``) and end the thread, a
    vanishing one would spin.

    Raises:
        ParameterError: ``period_s`` is not a finite number in [1 ms, 60 s].
    """

    def __init__(self, check: Callable[[], object], period_s: float, name: str) -> None:
        self._check = check
        self._period_s = WATCHDOG_PERIOD_S.check(period_s, "watchdog period_s")
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def start(self) -> None:
        """Start the thread (once)."""
        self._thread.start()

    def stop(self) -> None:
        """Ask the thread to stop and wait for it (unless called from the thread itself)."""
        self._stop.set()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join(timeout=max(1.0, 5 * self._period_s))

    @property
    def running(self) -> bool:
        """Whether the thread is alive."""
        return self._thread.is_alive()

    def _run(self) -> None:
        while not self._stop.wait(self._period_s):
            try:
                self._check()
            except Exception:  # keep watching: see the class docstring
                _log.exception("watchdog check failed")
