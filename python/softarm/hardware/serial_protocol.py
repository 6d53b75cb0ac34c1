"""The ASCII line protocol between the host and the gripper/sensor Arduino (version 2).

Framing (NMEA-like, one frame per line, printable ASCII, ``\\n``-terminated)::

    $<seq>,<CMD>[,<arg>...]*<CCCC>\\n          host → Arduino
    $<seq>,OK[,<value>...]*<CCCC>\\n           Arduino → host, success
    $<seq>,ERR,<code>[,<message>]*<CCCC>\\n    Arduino → host, refused/failed

* ``<seq>``: decimal 0–255 without leading zeros, chosen by the host, incremented per
  request and echoed in the reply, so a late reply to an earlier request is recognised.
* ``<CCCC>``: exactly four upper-case hex digits, the CRC-16/CCITT-FALSE (polynomial
  0x1021, initial value 0xFFFF, no reflection, no final XOR; ``crc("123456789") =
  0x29B1``) of every byte between ``$`` and ``*``. Protocol 1 used a two-digit XOR-8,
  which misses every error that flips the same bit in two bytes (about 4 % of random
  2-bit errors); a CRC-16 detects every 1-, 2- and 3-bit error in a frame this short.
* Only the canonical form is accepted: one ``$``, fields of printable ASCII (0x20–0x7E)
  without ``$``, ``*`` or ``,``, the upper-case CRC, ``\\n`` or ``\\r\\n``, at most
  :data:`MAX_FRAME_BYTES` bytes. Lower-case, short or padded hex, leading zeros: rejected
  (each alternative spelling would let a bit flip turn one valid frame into another).
* A line that does not start with ``$`` is not a frame (firmware debug output): the host
  skips it. A line that starts with ``$`` but fails these checks is a corrupted frame.

Example: ``$0,PING*42E4`` is answered by ``$0,OK,softarm-arduino,2*B277``.

Commands (all idempotent — absolute set-points or reads — so a retry is always safe):

========== ================ ===========================================================
command    arguments        reply values
========== ================ ===========================================================
``PING``   —                firmware name, protocol version (``2``)
``GRIP``   angle (deg)      the servo angle now commanded (deg), 0–180
``GPOS``   —                the servo angle commanded (deg), 0–180
``NIR``    —                ripeness index in [0, 1] from the palm NIR sensor
``PRES``   —                the optional pressure board: one value per channel (psi)
========== ================ ===========================================================
"""

from __future__ import annotations

import binascii
import re
from dataclasses import dataclass

from softarm.errors import HardwareError, HardwareUnavailableError

__all__ = [
    "MAX_FRAME_BYTES",
    "PROTOCOL_VERSION",
    "ChecksumError",
    "DeviceError",
    "DisconnectedError",
    "FrameError",
    "Reply",
    "SerialTimeoutError",
    "crc16",
    "decode_reply",
    "encode_frame",
    "parse_frame",
]

PROTOCOL_VERSION = 2
SEQ_MODULUS = 256
#: Longest frame, ``\r\n`` included. The longest real one (``PRES``, nine values) is
#: about 120 bytes; the bound is what keeps a babbling line from growing a buffer.
MAX_FRAME_BYTES = 256

_FORBIDDEN = set("$*,\r\n")
_FIELD_BYTE = rb"[\x20-\x23\x25-\x29\x2b-\x7e]"  # printable ASCII except $ and *
_FRAME = re.compile(rb"\$(" + _FIELD_BYTE + rb"+)\*([0-9A-F]{4})\r?\n")
_PROTOCOL_1 = re.compile(rb"\$" + _FIELD_BYTE + rb"+\*[0-9A-F]{2}\r?\n")
_SEQ = re.compile(r"0|[1-9][0-9]{0,2}")


class FrameError(HardwareError):
    """A line from the device is not a well-formed frame."""


class ChecksumError(FrameError):
    """A frame's CRC does not match its payload (line noise)."""


class SerialTimeoutError(HardwareError):
    """The device did not answer in time, after every retry."""


class DisconnectedError(HardwareUnavailableError):
    """The serial port went away during a session (cable pulled, board reset)."""


class DeviceError(HardwareError):
    """The device answered ``ERR``: it understood the request and refused or failed it."""


def crc16(payload: bytes | str) -> int:
    """CRC-16/CCITT-FALSE of ``payload`` (the bytes between ``$`` and ``*``).

    ``binascii.crc_hqx`` is the CCITT polynomial 0x1021, MSB first, without final XOR;
    the initial value 0xFFFF makes it CCITT-FALSE.
    """
    data = payload.encode("ascii") if isinstance(payload, str) else payload
    return binascii.crc_hqx(data, 0xFFFF)


def encode_frame(seq: int, *fields: object) -> bytes:
    """Encode ``$seq,field,...*CCCC\\n``.

    Raises:
        FrameError: ``seq`` is not an integer in 0–255, a field contains a reserved or
            non-printable character, or the frame exceeds :data:`MAX_FRAME_BYTES`.
    """
    if isinstance(seq, bool) or not isinstance(seq, int) or not 0 <= seq < SEQ_MODULUS:
        raise FrameError(f"seq must be an integer in [0, {SEQ_MODULUS - 1}], got {seq!r}")
    texts = [str(f) for f in fields]
    for text in texts:
        if _FORBIDDEN & set(text) or not all(" " <= c <= "~" for c in text):
            raise FrameError(f"frame field {text!r} contains a reserved or non-printable character")
    payload = ",".join([str(seq), *texts])
    frame = f"${payload}*{crc16(payload):04X}\n".encode("ascii")
    if len(frame) > MAX_FRAME_BYTES:
        raise FrameError(f"frame is {len(frame)} bytes, more than {MAX_FRAME_BYTES}: {frame!r}")
    return frame


def parse_frame(line: bytes) -> tuple[int, list[str]]:
    """Check one line (``\\n``-terminated) and split it into ``(seq, fields)``.

    Raises:
        ChecksumError: a canonical frame whose CRC does not match.
        FrameError: anything else malformed, including non-canonical spellings and
            protocol-1 frames (two-digit XOR checksum).
    """
    if len(line) > MAX_FRAME_BYTES:
        raise FrameError(f"frame is {len(line)} bytes, more than {MAX_FRAME_BYTES}")
    match = _FRAME.fullmatch(line)
    if match is None:
        if _PROTOCOL_1.fullmatch(line):
            raise FrameError(
                f"frame {line!r} has a protocol-1 XOR checksum; this host speaks protocol "
                f"{PROTOCOL_VERSION} (CRC-16): update the firmware"
            )
        raise FrameError(f"malformed frame {line!r}: expected $payload*CCCC\\n")
    payload, given = match.group(1), match.group(2)
    computed = crc16(payload)
    if computed != int(given, 16):
        raise ChecksumError(
            f"bad checksum in frame {line!r}: computed {computed:04X}, got {given.decode()}"
        )
    seq_text, *fields = payload.decode("ascii").split(",")
    if not _SEQ.fullmatch(seq_text) or int(seq_text) >= SEQ_MODULUS:
        raise FrameError(f"bad sequence number {seq_text!r} in frame {line!r}")
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
