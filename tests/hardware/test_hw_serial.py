"""The line protocol (pure functions) and ArduinoLink against a fake Arduino on a pty."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from fake_arduino import FakeArduino

from softarm.errors import HardwareError, HardwareUnavailableError, OutOfRangeError
from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.arduino_devices import (
    ArduinoGripper,
    ArduinoPressureMonitor,
    ArduinoRipenessSensor,
)
from softarm.hardware.serial_protocol import (
    ChecksumError,
    DeviceError,
    DisconnectedError,
    FrameError,
    SerialTimeoutError,
    checksum,
    decode_reply,
    encode_frame,
    parse_frame,
)


def test_frame_format_matches_nmea_style_xor() -> None:
    frame = encode_frame(7, "GRIP", "90.0")
    assert frame == b"$7,GRIP,90.0*" + f"{checksum('7,GRIP,90.0'):02X}".encode() + b"\n"
    assert checksum("7,GRIP,90.0") == np.bitwise_xor.reduce(np.frombuffer(b"7,GRIP,90.0", "u1"))
    assert parse_frame(frame) == (7, ["GRIP", "90.0"])
    assert parse_frame(frame.replace(b"\n", b"\r\n")) == (7, ["GRIP", "90.0"])


@pytest.mark.parametrize(
    ("line", "error"),
    [
        (b"$7,GRIP,91.0*" + encode_frame(7, "GRIP", "90.0")[-3:], ChecksumError),
        (b"7,GRIP*00\n", FrameError),
        (b"$7,GRIP\n", FrameError),
        (b"$7,GRIP*ZZ\n", FrameError),
        (b"$\xff*00\n", FrameError),
        (encode_frame(0, "X").replace(b"$0", b"$a"), FrameError),
    ],
)
def test_malformed_frames(line: bytes, error: type[Exception]) -> None:
    with pytest.raises(error):
        parse_frame(line)


def test_encode_rejects_reserved_characters_and_bad_seq() -> None:
    with pytest.raises(FrameError, match="reserved"):
        encode_frame(1, "GRIP", "1,2")
    with pytest.raises(FrameError, match="seq"):
        encode_frame(256, "PING")


def test_documented_example_frames() -> None:
    assert encode_frame(0, "PING") == b"$0,PING*0C\n"
    assert decode_reply(b"$0,OK,softarm-arduino,1*1E\n").values == ["softarm-arduino", "1"]


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
        assert link.ping() == "softarm-fake 1"
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
        assert link.ping() == "softarm-fake 1"
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
        assert link.ping() == "softarm-fake 1"  # the retry answers
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


def test_missing_port_is_unavailable(tmp_path) -> None:
    with pytest.raises(HardwareUnavailableError, match="ttyNOPE"):
        ArduinoLink(str(tmp_path / "ttyNOPE"))


def test_disconnect_mid_session(arduino: FakeArduino) -> None:
    link = link_to(arduino, timeout_s=0.3, retries=0)
    assert link.ping() == "softarm-fake 1"
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
