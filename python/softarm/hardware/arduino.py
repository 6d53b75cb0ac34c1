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

from softarm.errors import HardwareError, HardwareUnavailableError, ParameterError
from softarm.hardware.serial_protocol import (
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

    Args:
        port: device path (``/dev/ttyACM0``, ``COM3``) or any pyserial URL.
        baud: baud rate (the firmware's).
        timeout_s: how long one attempt waits for its reply.
        retries: extra attempts after a timeout or a corrupted reply.
        startup_delay_s: wait after opening: most Arduinos reset when the port opens and
            need about 2 s to boot.
        serial_factory: opens the port (tests pass a fake); default ``serial.serial_for_url``.

    Raises:
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
    ) -> None:
        if not timeout_s > 0.0:
            raise ParameterError(f"timeout_s must be > 0, got {timeout_s!r}")
        if retries < 0:
            raise ParameterError(f"retries must be >= 0, got {retries!r}")
        self.port = port
        self._timeout = timeout_s
        self._retries = retries
        self._seq = 0
        factory = serial_factory if serial_factory is not None else serial.serial_for_url
        try:
            self._serial: Any = factory(
                port, baudrate=baud, timeout=timeout_s, write_timeout=timeout_s
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
        for attempt in range(1 + self._retries):
            seq = self._next_seq()
            try:
                self._serial.reset_input_buffer()  # drop replies to abandoned requests
                self._serial.write(encode_frame(seq, command, *args))
                reply = self._await(seq, command)
            except (SerialTimeoutError, FrameError) as exc:
                _log.warning("%s on %s, attempt %d: %s", command, self.port, attempt + 1, exc)
                last = exc
                continue
            except _PORT_ERRORS as exc:
                raise DisconnectedError(
                    f"serial port {self.port!r} disconnected during {command}: {exc}"
                ) from exc
            if not reply.ok:
                raise DeviceError(
                    f"device on {self.port!r} refused {command} {list(args)}: "
                    f"{','.join(reply.values) or 'no detail'}"
                )
            return reply.values
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

    def _await(self, seq: int, command: str) -> Reply:
        deadline = time.monotonic() + self._timeout
        while (remaining := deadline - time.monotonic()) > 0.0:
            self._serial.timeout = remaining
            line = self._serial.readline()
            if not line.endswith(b"\n"):
                break  # pyserial timed out (possibly mid-line)
            reply = decode_reply(line)
            if reply.seq == seq:
                return reply
            _log.debug("dropping stale reply %r while waiting for seq %d", line, seq)
        raise SerialTimeoutError(f"no reply to {command} (seq {seq}) within {self._timeout} s")
