"""The ASCII line protocol between the host and the gripper/sensor Arduino.

Framing (NMEA-like, one frame per line, ASCII, ``\\n``-terminated)::

    $<seq>,<CMD>[,<arg>...]*<HH>\\n          host → Arduino
    $<seq>,OK[,<value>...]*<HH>\\n           Arduino → host, success
    $<seq>,ERR,<code>[,<message>]*<HH>\\n    Arduino → host, refused/failed

* ``<seq>``: decimal 0–255, chosen by the host, incremented per request and echoed in the
  reply, so a late reply to an earlier (timed-out) request is recognised and dropped.
* ``<HH>``: two upper-case hex digits, the XOR of every byte between ``$`` and ``*``.
* Fields never contain ``$``, ``*``, ``,`` or line breaks. ``\\r`` before ``\\n`` is ignored.

Example: ``$0,PING*0C`` is answered by ``$0,OK,softarm-arduino,1*1E``.

Commands (all idempotent — absolute set-points or reads — so a retry is always safe):

========== ================ ===========================================================
command    arguments        reply values
========== ================ ===========================================================
``PING``   —                firmware name, protocol version (``1``)
``GRIP``   angle (deg)      the servo angle now commanded (deg), 0–180
``GPOS``   —                the servo angle commanded (deg)
``NIR``    —                ripeness index in [0, 1] from the palm NIR sensor
``PRES``   —                the optional pressure board: one value per channel (psi)
========== ================ ===========================================================
"""

from __future__ import annotations

from dataclasses import dataclass

from softarm.errors import HardwareError, HardwareUnavailableError

__all__ = [
    "PROTOCOL_VERSION",
    "ChecksumError",
    "DeviceError",
    "DisconnectedError",
    "FrameError",
    "Reply",
    "SerialTimeoutError",
    "checksum",
    "decode_reply",
    "encode_frame",
    "parse_frame",
]

PROTOCOL_VERSION = 1
SEQ_MODULUS = 256
_FORBIDDEN = set("$*,\r\n")


class FrameError(HardwareError):
    """A line from the device is not a well-formed frame."""


class ChecksumError(FrameError):
    """A frame's checksum does not match its payload (line noise)."""


class SerialTimeoutError(HardwareError):
    """The device did not answer in time, after every retry."""


class DisconnectedError(HardwareUnavailableError):
    """The serial port went away during a session (cable pulled, board reset)."""


class DeviceError(HardwareError):
    """The device answered ``ERR``: it understood the request and refused or failed it."""


def checksum(payload: str) -> int:
    """XOR of the payload's bytes (the text between ``$`` and ``*``)."""
    value = 0
    for byte in payload.encode("ascii"):
        value ^= byte
    return value


def encode_frame(seq: int, *fields: object) -> bytes:
    """Encode ``$seq,field,...*HH\\n``.

    Raises:
        FrameError: ``seq`` is outside 0–255 or a field contains a reserved character.
    """
    if not 0 <= seq < SEQ_MODULUS:
        raise FrameError(f"seq must lie in [0, {SEQ_MODULUS - 1}], got {seq}")
    texts = [str(f) for f in fields]
    for text in texts:
        if _FORBIDDEN & set(text) or not text.isascii():
            raise FrameError(f"frame field {text!r} contains a reserved or non-ASCII character")
    payload = ",".join([str(seq), *texts])
    return f"${payload}*{checksum(payload):02X}\n".encode("ascii")


def parse_frame(line: bytes) -> tuple[int, list[str]]:
    """Check and split one line into ``(seq, fields)``.

    Raises:
        ChecksumError: the checksum does not match.
        FrameError: anything else malformed.
    """
    try:
        text = line.decode("ascii").rstrip("\r\n")
    except UnicodeDecodeError as exc:
        raise FrameError(f"frame is not ASCII: {line!r}") from exc
    if not text.startswith("$") or len(text) < 4 or text[-3] != "*":
        raise FrameError(f"malformed frame {text!r}: expected $payload*HH")
    payload, given = text[1:-3], text[-2:]
    try:
        expected = int(given, 16)
    except ValueError as exc:
        raise FrameError(f"malformed checksum {given!r} in frame {text!r}") from exc
    if checksum(payload) != expected:
        raise ChecksumError(
            f"bad checksum in frame {text!r}: computed {checksum(payload):02X}, got {given}"
        )
    seq_text, *fields = payload.split(",")
    if not seq_text.isdigit() or int(seq_text) >= SEQ_MODULUS:
        raise FrameError(f"bad sequence number {seq_text!r} in frame {text!r}")
    return int(seq_text), fields


@dataclass(frozen=True)
class Reply:
    """A decoded reply: its sequence number, ``ok`` (``OK`` vs ``ERR``) and the values
    that follow the status field."""

    seq: int
    ok: bool
    values: list[str]


def decode_reply(line: bytes) -> Reply:
    """Parse a reply line into a :class:`Reply` (the caller checks ``seq`` and ``ok``)."""
    seq, fields = parse_frame(line)
    if fields[:1] == ["OK"]:
        return Reply(seq, True, fields[1:])
    if fields[:1] == ["ERR"]:
        return Reply(seq, False, fields[1:])
    raise FrameError(f"reply {line!r} is neither OK nor ERR")
