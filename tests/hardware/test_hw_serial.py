"""The line protocol (pure functions) and ArduinoLink against a fake Arduino on a pty."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from fake_arduino import FakeArduino

from softarm.errors import (
    HardwareError,
    HardwareUnavailableError,
    OutOfRangeError,
    ParameterError,
)
from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.arduino_devices import (
    ArduinoGripper,
    ArduinoPressureMonitor,
    ArduinoRipenessSensor,
    ReadingError,
)
from softarm.hardware.serial_protocol import (
    MAX_FRAME_BYTES,
    ChecksumError,
    DeviceError,
    DisconnectedError,
    FrameError,
    SerialTimeoutError,
    crc16,
    decode_reply,
    encode_frame,
    parse_frame,
)


def test_frame_format_carries_a_crc16_ccitt_false() -> None:
    assert crc16("123456789") == 0x29B1  # the catalogued check value of CRC-16/CCITT-FALSE
    frame = encode_frame(7, "GRIP", "90.0")
    assert frame == b"$7,GRIP,90.0*" + f"{crc16('7,GRIP,90.0'):04X}".encode() + b"\n"
    assert parse_frame(frame) == (7, ["GRIP", "90.0"])
    assert parse_frame(frame.replace(b"\n", b"\r\n")) == (7, ["GRIP", "90.0"])


def with_crc(payload: bytes, crc_text: bytes | None = None, end: bytes = b"\n") -> bytes:
    text = crc_text if crc_text is not None else f"{crc16(payload):04X}".encode()
    return b"$" + payload + b"*" + text + end


@pytest.mark.parametrize(
    ("line", "error"),
    [
        (b"$7,GRIP,91.0*" + encode_frame(7, "GRIP", "90.0")[-5:], ChecksumError),
        (b"7,GRIP*0000\n", FrameError),
        (b"$7,GRIP\n", FrameError),
        (b"$7,GRIP*ZZZZ\n", FrameError),
        (b"$\xff*0000\n", FrameError),
        (encode_frame(0, "X").replace(b"$0", b"$a"), FrameError),
        # Canonical form only: each alternative spelling would let noise pass.
        (with_crc(b"7,GRIP", f"{crc16('7,GRIP'):04x}".encode()), FrameError),  # lower case
        (with_crc(b"7,GRIP", f"{crc16('7,GRIP'):X}".encode()[1:]), FrameError),  # 3 digits
        (with_crc(b"7,GRIP", f"{crc16('7,GRIP'):05X}".encode()), FrameError),  # 5 digits
        (with_crc(b"7,GRIP", b" " + f"{crc16('7,GRIP'):04X}".encode()[1:]), FrameError),
        (with_crc(b"07,GRIP"), FrameError),  # leading zero in seq
        (with_crc(b"+7,GRIP"), FrameError),
        (with_crc(b"256,GRIP"), FrameError),
        (with_crc(b"7,GR\tIP"), FrameError),  # control character
        (with_crc(b"7,GRIP$"), FrameError),
        (with_crc(b"7,GRIP", end=b""), FrameError),  # no newline
        (with_crc(b"7,GRIP", end=b"\n\n"), FrameError),
        (b"$" + with_crc(b"7,GRIP"), FrameError),
        (with_crc(b"7," + b"9" * MAX_FRAME_BYTES), FrameError),  # over-long
        (b"$0,PING*0C\n", FrameError),  # a protocol-1 frame (XOR-8)
    ],
)
def test_malformed_frames(line: bytes, error: type[Exception]) -> None:
    with pytest.raises(error):
        parse_frame(line)


def test_protocol_1_frames_are_named_as_such() -> None:
    with pytest.raises(FrameError, match=r"protocol-1 XOR checksum.*update the firmware"):
        parse_frame(b"$0,OK,softarm-arduino,1*1E\r\n")


def flip(frame: bytes, *bits: int) -> bytes:
    out = bytearray(frame)
    for bit in bits:
        out[bit // 8] ^= 1 << (bit % 8)
    return bytes(out)


def test_every_two_bit_corruption_of_the_issue_frame_is_rejected() -> None:
    """Exhaustive: XOR-8 accepted `$5,OK,0.75*2D` with two flipped bits as 0.64."""
    frame = encode_frame(5, "OK", "0.75")
    n = 8 * len(frame)
    accepted = []
    for i in range(n):
        for j in range(i + 1, n):
            try:
                accepted.append(parse_frame(flip(frame, i, j)))
            except FrameError:
                pass
    assert accepted == []


def test_random_two_bit_corruptions_are_all_rejected() -> None:
    """50,000 random 2-bit corruptions of random frames (seed 12), as in the issue."""
    rng = np.random.default_rng(12)
    alphabet = np.frombuffer(b"0123456789.-ABCDEFGHIJKLMNOPQRSTUVWXYZ", dtype=np.uint8)
    accepted = 0
    for _ in range(500):
        fields = [
            bytes(rng.choice(alphabet, size=rng.integers(1, 12))).decode()
            for _ in range(rng.integers(1, 10))
        ]
        frame = encode_frame(int(rng.integers(0, 256)), *fields)
        first = rng.integers(0, 8 * len(frame), size=100)
        second = (first + rng.integers(1, 8 * len(frame), size=100)) % (8 * len(frame))
        for i, j in zip(first.tolist(), second.tolist(), strict=True):
            try:
                parse_frame(flip(frame, i, j))
                accepted += 1
            except FrameError:
                pass
    assert accepted == 0


def test_crc_detects_every_payload_bit_plus_crc_digit_flip_up_to_the_longest_frame() -> None:
    """The one 2-bit pattern the CRC's Hamming distance does not cover by itself: one
    payload bit and one bit of a CRC hex digit (a digit flip can change up to three bits
    of the CRC value, e.g. 'B' -> 'C'). The CRC is linear, so a payload bit flip changes
    it by a value that depends only on the payload length and the bit position; check
    that none equals a change a single digit flip can make, for every length a frame
    may have."""
    hexdigits = "0123456789ABCDEF"
    digit_changes = {
        (int(c, 16) ^ int(chr(ord(c) ^ (1 << b)), 16)) << (4 * pos)
        for pos in range(4)
        for c in hexdigits
        for b in range(8)
        if chr(ord(c) ^ (1 << b)) in hexdigits
    }
    for length in range(1, MAX_FRAME_BYTES - 6):
        zero = crc16(bytes(length))
        for bit in range(8 * length):
            change = crc16(flip(bytes(length), bit)) ^ zero
            assert change not in digit_changes, (length, bit)


def test_encode_rejects_reserved_characters_and_bad_seq() -> None:
    with pytest.raises(FrameError, match="reserved"):
        encode_frame(1, "GRIP", "1,2")
    with pytest.raises(FrameError, match="non-printable"):
        encode_frame(1, "GRIP", "1\t2")
    with pytest.raises(FrameError, match="seq"):
        encode_frame(256, "PING")
    with pytest.raises(FrameError, match="seq"):
        encode_frame(True, "PING")  # type: ignore[arg-type]
    with pytest.raises(FrameError, match="more than 256"):
        encode_frame(1, "X" * MAX_FRAME_BYTES)


def test_documented_example_frames() -> None:
    assert encode_frame(0, "PING") == b"$0,PING*42E4\n"
    assert decode_reply(b"$0,OK,softarm-arduino,2*B277\n").values == ["softarm-arduino", "2"]


def test_reply_status() -> None:
    assert decode_reply(encode_frame(3, "OK", "1.5")).values == ["1.5"]
    assert not decode_reply(encode_frame(3, "ERR", "RANGE")).ok
    with pytest.raises(FrameError, match="neither OK nor ERR"):
        decode_reply(encode_frame(3, "MAYBE"))


def link_to(fake: FakeArduino, **kwargs: float) -> ArduinoLink:
    return ArduinoLink(
        fake.path, timeout_s=kwargs.get("timeout_s", 0.5), retries=int(kwargs.get("retries", 2))
    )


def test_round_trip_gripper_sensor_and_pressures(arduino: FakeArduino) -> None:
    with link_to(arduino) as link:
        assert link.ping() == "softarm-fake 2"
        gripper = ArduinoGripper(link, open_deg=10.0, closed_deg=170.0)
        gripper.close()
        assert arduino.angle == 170.0 and gripper.position == pytest.approx(1.0)
        gripper.set_position(0.5)
        assert arduino.angle == 90.0
        gripper.open()
        assert gripper.position == pytest.approx(0.0)
        assert ArduinoRipenessSensor(link).read() == 0.75
        np.testing.assert_array_equal(ArduinoPressureMonitor(link)(), np.arange(9.0))
    seqs = [seq for seq, _ in arduino.requests]
    assert seqs == list(range(len(seqs)))  # one sequence number per request


def test_bad_checksum_is_retried_then_reported(arduino: FakeArduino) -> None:
    with link_to(arduino, retries=2) as link:
        arduino.corrupt = 1
        assert link.ping() == "softarm-fake 2"
        assert len(arduino.requests) == 2
        arduino.corrupt = 3
        with pytest.raises(ChecksumError, match="bad checksum"):
            link.ping()


def test_stale_reply_is_ignored(arduino: FakeArduino) -> None:
    with link_to(arduino) as link:
        link.ping()
        arduino.stale = 1
        assert ArduinoRipenessSensor(link).read() == 0.75
        assert len(arduino.requests) == 2


def test_timeout_then_recovery(arduino: FakeArduino) -> None:
    with link_to(arduino, timeout_s=0.2, retries=1) as link:
        arduino.silent = 1
        assert link.ping() == "softarm-fake 2"  # the retry answers
        arduino.silent = 2
        start = time.monotonic()
        with pytest.raises(SerialTimeoutError, match=r"PING.*0\.2 s.*2 attempts"):
            link.ping()
        assert 0.35 < time.monotonic() - start < 2.0


def test_device_error_is_not_retried(arduino: FakeArduino) -> None:
    with link_to(arduino) as link:
        with pytest.raises(DeviceError, match=r"GRIP.*RANGE"):
            link.request("GRIP", "200")
        assert len(arduino.requests) == 1


def test_sensor_values_are_validated(arduino: FakeArduino) -> None:
    with link_to(arduino) as link:
        sensor = ArduinoRipenessSensor(link)
        for raw, pattern in (("nan", "non-finite"), ("1.5", r"\[0, 1\]"), ("x", "numeric")):
            arduino.nir = raw
            with pytest.raises(HardwareError, match=pattern):
                sensor.read()
        with pytest.raises(OutOfRangeError, match="fraction"):
            ArduinoGripper(link).set_position(1.2)


@pytest.mark.parametrize(
    ("angle", "message"),
    [(-45.0, r"\[0, 180\] deg, got -45.0"), (181.0, r"\[0, 180\]"), (5.0, r"open 10°")],
)
def test_gripper_angles_outside_the_servo_or_configured_range_are_faults(
    arduino: FakeArduino, angle: float, message: str
) -> None:
    """Issue 12 item 14: -45° used to read as position -0.34."""
    with link_to(arduino) as link:
        gripper = ArduinoGripper(link, open_deg=10.0, closed_deg=170.0)
        arduino.angle = angle
        with pytest.raises(ReadingError, match=message):
            _ = gripper.position


def test_gripper_position_within_reporting_resolution_of_an_end_is_clipped(
    arduino: FakeArduino,
) -> None:
    with link_to(arduino) as link:
        gripper = ArduinoGripper(link, open_deg=10.04, closed_deg=169.96)
        gripper.open()  # commanded as "10.0": the firmware reports 0.1° steps
        assert arduino.angle == 10.0 and gripper.position == 0.0
        gripper.close()
        assert gripper.position == 1.0


@pytest.mark.parametrize(
    ("raw", "message"),
    [("-30.0", r"PRES channel 3 .* got -30.0"), ("1e300", "got 1e"), ("146.0", r"145\]")],
)
def test_pressure_readings_outside_the_physical_range_are_faults(
    arduino: FakeArduino, raw: str, message: str
) -> None:
    with link_to(arduino) as link:
        monitor = ArduinoPressureMonitor(link)
        arduino.pressures[3] = raw
        with pytest.raises(ReadingError, match=message):
            monitor.read_pressures()
        arduino.pressures[3] = "-0.4"  # a gauge offset at rest is fine
        assert monitor()[3] == -0.4


@pytest.mark.parametrize("raw", [" 1.5", "1_0", "infinity", "0x1", "1.", ".5"])
def test_readings_must_be_plain_decimals(arduino: FakeArduino, raw: str) -> None:
    with link_to(arduino) as link:
        arduino.nir = raw
        with pytest.raises(HardwareError):
            ArduinoRipenessSensor(link).read()


def test_monitor_parameters_are_checked(arduino: FakeArduino) -> None:
    with link_to(arduino) as link:
        for kwargs in ({"channels": 0}, {"channels": True}, {"valid_psi": (5.0, 1.0)}):
            with pytest.raises(ParameterError):
                ArduinoPressureMonitor(link, **kwargs)  # type: ignore[arg-type]


def test_link_settings_are_bounded(arduino: FakeArduino) -> None:
    """Issue 12 item 12: timeout_s or startup_delay_s = 1e308 raised OverflowError."""
    for kwargs, name in (
        ({"timeout_s": 1e308}, "timeout_s"),
        ({"timeout_s": 1e-9}, "timeout_s"),
        ({"timeout_s": float("nan")}, "timeout_s"),
        ({"startup_delay_s": 1e308}, "startup_delay_s"),
        ({"startup_delay_s": -1.0}, "startup_delay_s"),
        ({"retries": 10**6}, "retries"),
        ({"retries": 1.5}, "retries"),
        ({"retries": True}, "retries"),
        ({"baud": 10**30}, "baud"),
    ):
        with pytest.raises(ParameterError, match=name):
            ArduinoLink(arduino.path, **kwargs)  # type: ignore[arg-type]


def test_missing_port_is_unavailable(tmp_path) -> None:
    with pytest.raises(HardwareUnavailableError, match="ttyNOPE"):
        ArduinoLink(str(tmp_path / "ttyNOPE"))


def test_disconnect_mid_session(arduino: FakeArduino) -> None:
    link = link_to(arduino, timeout_s=0.3, retries=0)
    assert link.ping() == "softarm-fake 2"
    arduino.hang_up()
    with pytest.raises(DisconnectedError, match="disconnected during PING"):
        link.ping()
    assert issubclass(DisconnectedError, HardwareUnavailableError)
    link.close()
    link.close()  # harmless twice, even on a dead port


def test_disconnect_while_waiting_for_a_reply(arduino: FakeArduino) -> None:
    link = link_to(arduino, timeout_s=1.0, retries=0)
    arduino.silent = 1
    threading.Timer(0.1, arduino.hang_up).start()
    start = time.monotonic()
    with pytest.raises(DisconnectedError, match="disconnected during PING"):
        link.ping()
    assert time.monotonic() - start < 0.9  # reported as a disconnect, not as a timeout
    link.close()
