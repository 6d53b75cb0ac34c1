"""A fake gripper/sensor Arduino on a pseudo-terminal, speaking the line protocol.

pyserial opens :attr:`FakeArduino.path` (the pty's slave side) exactly as it would a
real ``/dev/ttyACM0``; a thread answers on the master side. Switches inject faults.
"""

from __future__ import annotations

import os
import select
import threading

from softarm.hardware.serial_protocol import checksum, encode_frame, parse_frame


class FakeArduino:
    """Firmware stand-in. Fault switches (counts are consumed one per request):
    ``silent`` ignore requests, ``corrupt`` send replies with a wrong checksum,
    ``stale`` precede the reply with one for an older sequence number."""

    def __init__(self) -> None:
        self.master, self._slave = os.openpty()
        self.path = os.ttyname(self._slave)
        self.angle = 90.0
        self.nir = "0.75"
        self.pressures = [str(float(i)) for i in range(9)]
        self.silent = 0
        self.corrupt = 0
        self.stale = 0
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
        reply = encode_frame(seq, *self._answer(fields))
        if self.corrupt > 0:
            self.corrupt -= 1
            good = f"{checksum(reply[1:-4].decode()):02X}".encode()
            bad = f"{(int(good, 16) ^ 0x5A):02X}".encode()
            reply = reply[:-3] + bad + b"\n"
        self._send(reply)

    def _answer(self, fields: list[str]) -> list[object]:
        command, args = fields[0], fields[1:]
        if command == "PING":
            return ["OK", "softarm-fake", 1]
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
