"""The wall clock of the hardware control loop."""

from __future__ import annotations

import time

__all__ = ["MonotonicClock"]


class MonotonicClock:
    """Wall-clock time; ``sleep`` waits for the next control period boundary."""

    def __init__(self) -> None:
        self._next = time.monotonic()

    def now(self) -> float:
        """Seconds since an arbitrary origin."""
        return time.monotonic()

    def sleep(self, dt: float) -> None:
        """Wait until ``dt`` after the previous deadline (no drift when a step is slow)."""
        self._next = max(self._next + dt, time.monotonic())
        time.sleep(max(0.0, self._next - time.monotonic()))
