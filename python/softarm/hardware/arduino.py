"""Serial link to the Arduino that runs the gripper servo, the NIR ripeness sensor and
the optional pressure board, speaking :mod:`softarm.hardware.serial_protocol`.

:class:`ArduinoLink` owns the port: framing, sequence numbers, a per-attempt timeout and
retries. Timeouts and corrupted replies are retried (every command is idempotent);
an ``ERR`` reply is not (the device understood and refused). Device classes on top of it
are in :mod:`softarm.hardware.arduino_devices`.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from types import TracebackType
from typing import Any

import serial

from softarm.errors import HardwareError, HardwareUnavailableError
from softarm.hardware.limits import BAUD, RETRIES, SERIAL_TIMEOUT_S, STARTUP_DELAY_S
from softarm.hardware.serial_protocol import (
    MAX_FRAME_BYTES,
    SEQ_MODULUS,
    DeviceError,
    DisconnectedError,
    FrameError,
    Reply,
    SerialTimeoutError,
    decode_reply,
    encode_frame,
)

__all__ = ["ArduinoLink"]

_log = logging.getLogger(__name__)

# What a vanished port raises: pyserial wraps most OS errors, but tcflush on a hung-up
# tty raises termios.error directly (POSIX only).
_PORT_ERRORS: tuple[type[BaseException], ...] = (serial.SerialException, OSError)
try:
    import termios

    _PORT_ERRORS = (*_PORT_ERRORS, termios.error)
except ImportError:  # Windows
    pass


class ArduinoLink:
    """A request/reply session with the Arduino over a serial port.

    A request ends within ``timeout_s × (1 + retries)`` whatever the line does: bytes are
    read in bounded chunks against each attempt's deadline, never with ``readline``
    (which waits for a newline as long as bytes keep coming), and a line longer than
    :data:`~softarm.hardware.serial_protocol.MAX_FRAME_BYTES` is dropped up to its
    newline, so a babbling device can neither hold a request nor grow a buffer. (A write
    that blocks is cut off by pyserial's ``write_timeout``, also ``timeout_s``.)

    Within an attempt, lines that are not frames of this request are skipped: debug
    text (not starting with ``$``) and well-formed replies to other sequence numbers.
    A reply to *any* attempt of the current request is accepted (commands are
    idempotent), and the input buffer is flushed only when a request starts, so a retry
    never throws away a valid reply that arrives late. A corrupted frame (starts with
    ``$`` but fails the CRC or the canonical form) ends the attempt at once: it was
    probably the reply.

    Args:
        port: device path (``/dev/ttyACM0``, ``COM3``) or any pyserial URL.
        baud: baud rate (the firmware's), an integer in [300, 4000000].
        timeout_s: how long one attempt waits for its reply, in [0.01, 10] s.
        retries: extra attempts after a timeout or a corrupted reply, 0–10.
        startup_delay_s: wait after opening, in [0, 10] s: most Arduinos reset when the
            port opens and need about 2 s to boot.
        serial_factory: opens the port (tests pass a fake); default ``serial.serial_for_url``.
        clock: monotonic time source for the deadlines (tests pass a virtual one).

    Raises:
        ParameterError: a setting outside its range (:mod:`softarm.hardware.limits`).
        HardwareUnavailableError: the port does not exist or cannot be opened.
    """

    def __init__(
        self,
        port: str,
        baud: int = 115200,
        timeout_s: float = 0.5,
        retries: int = 2,
        *,
        startup_delay_s: float = 0.0,
        serial_factory: Callable[..., Any] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._timeout = SERIAL_TIMEOUT_S.check(timeout_s)
        self._retries = int(RETRIES.check(retries))
        baud = int(BAUD.check(baud))
        startup_delay_s = STARTUP_DELAY_S.check(startup_delay_s)
        self.port = port
        self._clock = clock
        self._seq = 0
        self._rx = bytearray()  # bytes read but not yet split into lines
        self._discarding = False  # inside an over-long line: drop up to its newline
        factory = serial_factory if serial_factory is not None else serial.serial_for_url
        try:
            self._serial: Any = factory(
                port, baudrate=baud, timeout=self._timeout, write_timeout=self._timeout
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            raise HardwareUnavailableError(
                f"cannot open serial port {port!r} at {baud} baud: {exc}"
            ) from exc
        if startup_delay_s > 0.0:
            time.sleep(startup_delay_s)

    def request(self, command: str, *args: object) -> list[str]:
        """Send ``command`` with ``args`` and return the values of the ``OK`` reply.

        Raises:
            DeviceError: the device answered ``ERR``.
            SerialTimeoutError: no valid reply after ``1 + retries`` attempts.
            ChecksumError / FrameError: the last attempt got a corrupted reply.
            DisconnectedError: the port went away.
        """
        last: HardwareError | None = None
        seqs: set[int] = set()  # every attempt of this request: any of them may answer
        try:
            # Only bytes that arrived before this request are flushed: none can be its reply.
            self._serial.reset_input_buffer()
            self._rx.clear()
            self._discarding = False
            for attempt in range(1 + self._retries):
                seq = self._next_seq()
                seqs.add(seq)
                frame = encode_frame(seq, command, *args)  # a bad argument is not retried
                deadline = self._clock() + self._timeout  # the write counts against it too
                try:
                    self._serial.write(frame)
                    reply = self._await(seqs, command, deadline)
                except (SerialTimeoutError, FrameError) as exc:
                    _log.warning("%s on %s, attempt %d: %s", command, self.port, attempt + 1, exc)
                    last = exc
                    continue
                if not reply.ok:
                    raise DeviceError(
                        f"device on {self.port!r} refused {command} {list(args)}: "
                        f"{','.join(reply.values) or 'no detail'}"
                    )
                return reply.values
        except _PORT_ERRORS as exc:
            raise DisconnectedError(
                f"serial port {self.port!r} disconnected during {command}: {exc}"
            ) from exc
        assert last is not None  # the loop ran at least once and every pass set it
        if isinstance(last, SerialTimeoutError):
            raise SerialTimeoutError(
                f"no reply to {command} from {self.port!r} within {self._timeout} s "
                f"after {1 + self._retries} attempts"
            ) from last
        raise last

    def ping(self) -> str:
        """Check the firmware answers; returns its ``name version``."""
        return " ".join(self.request("PING"))

    def close(self) -> None:
        """Close the port. Calling it twice is harmless."""
        try:
            self._serial.close()
        except _PORT_ERRORS as exc:
            _log.warning("closing %s: %s", self.port, exc)

    def __enter__(self) -> ArduinoLink:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def _next_seq(self) -> int:
        seq = self._seq
        self._seq = (self._seq + 1) % SEQ_MODULUS
        return seq

    def _await(self, seqs: set[int], command: str, deadline: float) -> Reply:
        """The first reply to one of ``seqs`` before ``deadline``, skipping other lines."""
        while (line := self._read_line(deadline)) is not None:
            if not line.startswith(b"$"):
                _log.debug("skipping non-frame line %r from %s", line[:80], self.port)
                continue
            reply = decode_reply(line)  # a corrupted frame ends the attempt (retried)
            if reply.seq in seqs:
                return reply
            _log.debug("dropping stale reply %r while waiting for seq %s", line, sorted(seqs))
        raise SerialTimeoutError(
            f"no reply to {command} (seq {max(seqs)}) within {self._timeout} s"
        )

    def _read_line(self, deadline: float) -> bytes | None:
        """One ``\\n``-terminated line of at most ``MAX_FRAME_BYTES``, or ``None`` at the
        deadline. Over-long lines are dropped whole; each read waits at most until the
        deadline, so the call returns by then whatever arrives."""
        while True:
            end = self._rx.find(b"\n")
            if end >= 0:
                line = bytes(self._rx[: end + 1])
                del self._rx[: end + 1]
                if self._discarding:  # the tail of an over-long line
                    self._discarding = False
                    continue
                return line
            if len(self._rx) >= MAX_FRAME_BYTES:
                _log.debug(
                    "dropping a line longer than %d bytes from %s", MAX_FRAME_BYTES, self.port
                )
                self._rx.clear()
                self._discarding = True
            remaining = deadline - self._clock()
            if remaining <= 0.0:
                return None
            # Whatever is already buffered (returns at once), else one byte waiting at most
            # until the deadline; never more than MAX_FRAME_BYTES, so the buffer stays
            # below twice that.
            waiting = int(self._serial.in_waiting)
            if waiting > 0:
                self._rx += self._serial.read(min(waiting, MAX_FRAME_BYTES))
            else:
                self._serial.timeout = remaining
                self._rx += self._serial.read(1)
