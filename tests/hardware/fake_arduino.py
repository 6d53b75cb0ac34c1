"""A fake gripper/sensor Arduino on a pseudo-terminal, speaking the line protocol.

pyserial opens :attr:`FakeArduino.path` (the pty's slave side) exactly as it would a
real ``/dev/ttyACM0``; a thread answers on the master side. Switches inject faults.
"""

from __future__ import annotations

import os
import select
import threading
import time

from softarm.hardware.serial_protocol import PROTOCOL_VERSION, encode_frame, parse_frame


class FakeArduino:
    """Firmware stand-in. Fault switches (counts are consumed one per request):
    ``silent`` ignore requests, ``corrupt`` send replies with a wrong checksum,
    ``stale`` precede the reply with one for an older sequence number, ``debug`` precede
    it with a line of firmware debug text (not a frame)."""

    def __init__(self) -> None:
        self.master, self._slave = os.openpty()
        self.path = os.ttyname(self._slave)
        self.angle = 90.0
        self.nir = "0.75"
        self.pressures = [str(float(i)) for i in range(9)]
        self.silent = 0
        self.corrupt = 0
        self.stale = 0
        self.debug = 0
        self._quiet = threading.Event()
        self.requests: list[tuple[int, list[str]]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def hang_up(self) -> None:
        """Simulate pulling the cable: stop answering and close both pty ends."""
        self._stop.set()
        self._thread.join(timeout=2)
        for fd in (self.master, self._slave):
            try:
                os.close(fd)
            except OSError:
                pass

    close = hang_up

    def babble(self, duration_s: float) -> threading.Thread:
        """Send bytes without a newline for ``duration_s`` s (or until :meth:`stop_babble`)
        from a thread, returned so a test can see whether it is still babbling."""
        self._quiet = threading.Event()
        end = time.monotonic() + duration_s

        def run() -> None:
            while not self._quiet.is_set() and time.monotonic() < end:
                _, writable, _ = select.select([], [self.master], [], 0.01)
                if writable:
                    try:
                        os.write(self.master, b"A" * 64)
                    except OSError:
                        return

        thread = threading.Thread(target=run, daemon=True)
        thread.start()
        return thread

    def stop_babble(self) -> None:
        """End a :meth:`babble`."""
        self._quiet.set()

    def _run(self) -> None:
        buffer = b""
        while not self._stop.is_set():
            ready, _, _ = select.select([self.master], [], [], 0.02)
            if not ready:
                continue
            try:
                buffer += os.read(self.master, 1024)
            except OSError:
                return
            while b"\n" in buffer:
                line, buffer = buffer.split(b"\n", 1)
                self._handle(line + b"\n")

    def _handle(self, line: bytes) -> None:
        seq, fields = parse_frame(line)
        self.requests.append((seq, fields))
        if self.silent > 0:
            self.silent -= 1
            return
        if self.stale > 0:
            self.stale -= 1
            self._send(encode_frame((seq - 1) % 256, "OK", "stale"))
        if self.debug > 0:
            self.debug -= 1
            self._send(b"servo: attached, nir: warm\r\n")
        reply = encode_frame(seq, *self._answer(fields))
        if self.corrupt > 0:
            self.corrupt -= 1
            good = int(reply[-5:-1], 16)
            reply = reply[:-5] + f"{good ^ 0x5A5A:04X}".encode() + b"\n"
        self._send(reply)

    def _answer(self, fields: list[str]) -> list[object]:
        command, args = fields[0], fields[1:]
        if command == "PING":
            return ["OK", "softarm-fake", PROTOCOL_VERSION]
        if command == "GRIP":
            angle = float(args[0])
            if not 0.0 <= angle <= 180.0:
                return ["ERR", "RANGE", "angle out of range"]
            self.angle = angle
            return ["OK", f"{angle:.1f}"]
        if command == "GPOS":
            return ["OK", f"{self.angle:.1f}"]
        if command == "NIR":
            return ["OK", self.nir]
        if command == "PRES":
            return ["OK", *self.pressures]
        return ["ERR", "UNKNOWN", command]

    def _send(self, data: bytes) -> None:
        os.write(self.master, data)
