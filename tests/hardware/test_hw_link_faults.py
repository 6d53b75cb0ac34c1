"""ArduinoLink against a scripted port on a virtual clock: babbling lines, over-long
lines, debug text, late and corrupted replies (issue 12, items 1 and 3).

Times are virtual (the port advances its clock instead of sleeping), so the bounds below
are exact and the tests cannot be flaky on a loaded machine.
"""

from __future__ import annotations

import pytest
import serial
from fake_arduino import FakeArduino
from scripted_port import Arrivals, ScriptedPort, babble

from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.serial_protocol import (
    MAX_FRAME_BYTES,
    ChecksumError,
    DisconnectedError,
    SerialTimeoutError,
    encode_frame,
)

TIMEOUT = 0.2


def open_link(port: ScriptedPort, retries: int) -> ArduinoLink:
    return ArduinoLink(
        "scripted", timeout_s=TIMEOUT, retries=retries,
        serial_factory=lambda *a, **k: port, clock=port.clock,
    )  # fmt: skip


def ok(seq: int, *values: object) -> bytes:
    return encode_frame(seq, "OK", *values)


@pytest.mark.parametrize("retries", [0, 2])
def test_a_babbling_line_cannot_hold_a_request(retries: int) -> None:
    """The issue's reproducer: bytes without a newline for 10 s held a request for 10 s
    against a 0.2 s x attempts bound."""
    port = ScriptedPort(lambda seq, fields: babble(10.0))
    link = open_link(port, retries)
    start = port.clock()
    with pytest.raises(SerialTimeoutError, match="PING"):
        link.request("PING")
    attempts = 1 + retries
    # Each read waits at most until the attempt's deadline, so the bound is exact.
    assert port.clock() - start <= TIMEOUT * attempts + 1e-9
    assert port.largest_read <= MAX_FRAME_BYTES  # bounded reads, bounded buffer
    assert len(port.requests) == attempts


def test_a_megabyte_line_arriving_at_once_is_dropped_within_the_timeout() -> None:
    port = ScriptedPort(lambda seq, fields: [(0.0, b"x" * 1_000_000)])
    link = open_link(port, retries=0)
    start = port.clock()
    with pytest.raises(SerialTimeoutError):
        link.request("PING")
    assert port.clock() - start <= TIMEOUT + 1e-9
    assert port.largest_read <= MAX_FRAME_BYTES


def test_an_over_long_line_is_dropped_and_the_reply_after_it_accepted() -> None:
    port = ScriptedPort(lambda seq, fields: [(0.01, b"#" * 5000 + b"\n"), (0.02, ok(seq, "1"))])
    link = open_link(port, retries=0)
    assert link.request("GPOS") == ["1"]
    # Neither the junk's tail nor the reply is lost when the junk exceeds the bound,
    # even when the reply follows on the heels of the junk's newline.
    port = ScriptedPort(lambda seq, fields: [(0.01, b"#" * 5000 + b"\n" + ok(seq, "2"))])
    assert open_link(port, retries=0).request("GPOS") == ["2"]


def test_a_debug_line_before_every_reply_is_skipped_not_retried() -> None:
    """A stray line used to fail the attempt, and the retry's flush threw the reply away:
    with a debug line before every reply, every attempt failed."""

    def respond(seq: int, fields: list[str]) -> Arrivals:
        return [(0.01, b"servo: attached\r\n"), (0.02, ok(seq, "0.75"))]

    port = ScriptedPort(respond)
    link = open_link(port, retries=2)
    for _ in range(3):
        assert link.request("NIR") == ["0.75"]
    assert len(port.requests) == 3  # one attempt each


def test_a_late_reply_to_the_first_attempt_is_accepted_during_the_retry() -> None:
    def respond(seq: int, fields: list[str]) -> Arrivals:
        # The first attempt's reply arrives after its timeout; the retry gets no reply.
        return [(1.5 * TIMEOUT, ok(seq, "late"))] if seq == 0 else []

    port = ScriptedPort(respond)
    link = open_link(port, retries=1)
    assert link.request("GPOS") == ["late"]
    assert [seq for seq, _ in port.requests] == [0, 1]


def test_a_corrupted_frame_ends_the_attempt_but_the_retry_keeps_the_real_reply() -> None:
    def respond(seq: int, fields: list[str]) -> Arrivals:
        if seq != 0:
            return []
        good = ok(seq, "0.75")
        bad = good[:-5] + f"{int(good[-5:-1], 16) ^ 1:04X}".encode() + b"\n"
        return [(0.01, bad), (0.05, good)]  # noise, then the reply itself

    port = ScriptedPort(respond)
    link = open_link(port, retries=1)
    assert link.request("NIR") == ["0.75"]
    assert len(port.requests) == 2  # the corrupted frame ended attempt 1 early


def test_corrupted_replies_on_every_attempt_report_a_checksum_error() -> None:
    def respond(seq: int, fields: list[str]) -> Arrivals:
        good = ok(seq, "0.75")
        return [(0.01, good[:-5] + b"0000\n")]

    port = ScriptedPort(respond)
    with pytest.raises(ChecksumError, match="bad checksum"):
        open_link(port, retries=2).request("NIR")
    assert len(port.requests) == 3


def test_replies_to_earlier_requests_are_skipped() -> None:
    port = ScriptedPort(
        lambda seq, fields: [(0.0, ok((seq - 1) % 256, "old")), (0.01, ok(seq, "new"))]
    )
    link = open_link(port, retries=0)
    assert link.request("GPOS") == ["new"]
    assert link.request("GPOS") == ["new"]


def test_a_port_error_while_reading_is_a_disconnect() -> None:
    port = ScriptedPort(lambda seq, fields: [])

    def dead(size: int = 1) -> bytes:
        raise serial.SerialException("device reports readiness to read but returned no data")

    port.read = dead  # type: ignore[method-assign]
    with pytest.raises(DisconnectedError, match="disconnected during PING"):
        open_link(port, retries=2).request("PING")


def test_a_babbling_pty_cannot_hold_a_request(arduino: FakeArduino) -> None:
    """The same on a real pseudo-terminal through pyserial: the babble lasts 30 s, the
    request must give up long before (its bound is 0.2 s x 2 attempts)."""
    arduino.silent = 2
    with ArduinoLink(arduino.path, timeout_s=TIMEOUT, retries=1) as link:
        babbler = arduino.babble(30.0)
        try:
            with pytest.raises(SerialTimeoutError):
                link.ping()
            assert babbler.is_alive(), "the request only ended when the babbling stopped"
        finally:
            arduino.stop_babble()
        babbler.join(timeout=5.0)
        assert link.request("GPOS") == ["90.0"]  # the line recovers once the babble ends
