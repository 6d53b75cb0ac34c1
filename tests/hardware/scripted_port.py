"""An in-memory serial port on a virtual clock, for deterministic ArduinoLink tests.

Bytes "arrive" at scripted virtual times; ``read`` behaves like pyserial's (returns as
soon as ``size`` bytes are there, else when ``timeout`` has passed) but advances the
virtual clock instead of sleeping, so a test of a 10 s babbling line runs in
milliseconds and its timing assertions are exact, not wall-clock guesses.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable

from softarm.hardware.serial_protocol import parse_frame

Arrivals = list[tuple[float, bytes]]  # (delay after the request is written, bytes)


class VirtualClock:
    """A monotonic clock that only moves when the port waits."""

    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


class ScriptedPort:
    """A fake ``serial.Serial``: ``respond(seq, fields)`` scripts what each request
    written to it brings back, as ``(delay_s, bytes)`` arrivals."""

    def __init__(self, respond: Callable[[int, list[str]], Arrivals]) -> None:
        self.clock = VirtualClock()
        self.timeout: float | None = None
        self.requests: list[tuple[int, list[str]]] = []
        self.largest_read = 0
        self._respond = respond
        self._pending: list[tuple[float, int, bytes]] = []  # (time, order, data), sorted
        self._order = 0
        self._rx = bytearray()

    # The pyserial surface ArduinoLink uses.

    def write(self, data: bytes) -> int:
        seq, fields = parse_frame(data)
        self.requests.append((seq, fields))
        self.schedule(self._respond(seq, fields))
        return len(data)

    def schedule(self, arrivals: Arrivals) -> None:
        for delay, data in arrivals:
            self._order += 1
            bisect.insort(self._pending, (self.clock.now + delay, self._order, data))

    @property
    def in_waiting(self) -> int:
        self._deliver()
        return len(self._rx)

    def read(self, size: int = 1) -> bytes:
        self.largest_read = max(self.largest_read, size)
        deadline = self.clock.now + (self.timeout if self.timeout is not None else 1e9)
        self._deliver()
        while len(self._rx) < size:
            if not self._pending or self._pending[0][0] > deadline:
                self.clock.now = max(self.clock.now, deadline)
                break
            self.clock.now = max(self.clock.now, self._pending[0][0])
            self._deliver()
        out = bytes(self._rx[:size])
        del self._rx[:size]
        return out

    def readline(self) -> bytes:
        """What ``io.RawIOBase.readline`` does on a pyserial port: ``read(1)`` until a
        newline, each read with the port's timeout (so bytes that keep coming keep it
        going). Only the pre-fix ArduinoLink called this."""
        line = bytearray()
        while not line.endswith(b"\n"):
            byte = self.read(1)
            if not byte:
                break
            line += byte
        return bytes(line)

    def reset_input_buffer(self) -> None:
        self._deliver()
        self._rx.clear()

    def close(self) -> None:
        pass

    def _deliver(self) -> None:
        while self._pending and self._pending[0][0] <= self.clock.now:
            self._rx += self._pending.pop(0)[2]


def babble(duration_s: float, bytes_per_s: float = 11_520.0, chunk_s: float = 0.001) -> Arrivals:
    """Bytes without a newline for ``duration_s`` (115200 baud ≈ 11520 bytes/s)."""
    per_chunk = max(1, round(bytes_per_s * chunk_s))
    return [(i * chunk_s, b"A" * per_chunk) for i in range(round(duration_s / chunk_s))]
