"""The one reader and writer of image files: OpenCV is handed bytes, never a path.

``cv2.imread`` and ``cv2.imwrite`` take the path as a C string: a name that is not
UTF-8 (Python keeps its bytes as surrogate escapes) crashes OpenCV with a segmentation
fault. And ``imread`` decodes whatever size the header claims: a 1 MB PNG of
20000 x 20000 pixels costs 1.2 GB before anything can look at it. Here Python opens the
file (:func:`~softarm.files.read.open_regular`: a regular file of bounded size), the
header's size is checked against :data:`MAX_PIXELS` and :data:`MAX_DECODED_BYTES` before
``cv2.imdecode`` runs, and an image is written by ``cv2.imencode`` into a buffer that
Python writes. Only PNG, JPEG, BMP, TIFF and WebP are read (the formats whose header is
checked here); every failure is one line naming the file.

``cv2`` is imported by the functions that need it, so this leaf stays cheap to import.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.errors import InputError, OutputError, SoftarmError
from softarm.files.read import open_regular
from softarm.files.write import check_target, output_error

__all__ = [
    "MAX_DECODED_BYTES",
    "MAX_FILE_BYTES",
    "MAX_PIXELS",
    "decode_image",
    "encode_image",
    "image_header",
    "read_image",
    "read_image_bytes",
    "write_image",
]

#: Most pixels an image may have (40 M: an 8K frame is 33 M, a ZED2 2K side-by-side 5.5 M).
MAX_PIXELS = 40_000_000
#: Most bytes its pixels may take decoded in their own format (16-bit, alpha): 256 MiB.
MAX_DECODED_BYTES = 256 * 2**20
#: Largest image file read (256 MiB: an uncompressed 40 M pixel BGR image is 120 MB).
MAX_FILE_BYTES = 256 * 2**20

_PNG = b"\x89PNG\r\n\x1a\n"
# PNG colour type -> samples per pixel (grey, RGB, palette, grey+alpha, RGBA).
_PNG_SAMPLES = {0: 1, 2: 3, 3: 3, 4: 2, 6: 4}
# JPEG start-of-frame markers (SOF0-SOF15 but DHT, JPG and DAC, which share the range).
_JPEG_SOF = set(range(0xC0, 0xD0)) - {0xC4, 0xC8, 0xCC}


def image_header(data: bytes) -> tuple[int, int, int] | None:
    """(width, height, bytes per pixel decoded) from a PNG, JPEG, BMP, TIFF or WebP header,
    or None when ``data`` starts as none of them (or its header is cut short)."""
    try:
        if data.startswith(_PNG):
            w, h, depth, colour = struct.unpack(">IIBB", data[16:26])
            return w, h, _PNG_SAMPLES.get(colour, 4) * (2 if depth == 16 else 1)
        if data.startswith(b"\xff\xd8"):
            return _jpeg(data)
        if data.startswith(b"BM"):
            w, h = struct.unpack("<ii", data[18:26])
            return abs(w), abs(h), 4
        if data[:4] in (b"II*\x00", b"MM\x00*"):
            return _tiff(data)
        if data[:4] == b"RIFF" and data[8:12] == b"WEBP":
            return _webp(data)
    except struct.error:  # a header cut short
        return None
    return None


def _jpeg(data: bytes) -> tuple[int, int, int] | None:
    """Walk the segments to the first start-of-frame: its height, width, components."""
    at = 2
    while at + 4 <= len(data):
        if data[at] != 0xFF:
            return None
        marker = data[at + 1]
        if marker == 0xFF:  # fill byte
            at += 1
            continue
        if marker in (0x01, *range(0xD0, 0xD8)):  # no length: TEM, RSTn
            at += 2
            continue
        if marker in _JPEG_SOF:
            bits, h, w, n = struct.unpack(">BHHB", data[at + 4 : at + 10])
            return w, h, max(n, 1) * (2 if bits > 8 else 1)
        if marker == 0xDA:  # start of scan before any frame header
            return None
        at += 2 + struct.unpack(">H", data[at + 2 : at + 4])[0]
    return None


def _webp(data: bytes) -> tuple[int, int, int] | None:
    """The canvas of a WebP file's first chunk (RFC 9649): VP8X's 24-bit sizes less one,
    VP8L's 14-bit sizes less one after its signature byte, VP8's 14-bit sizes after the
    key frame's start code; 4 bytes a pixel (an alpha channel may come with any)."""
    chunk = data[12:16]
    if chunk == b"VP8X":
        w = int.from_bytes(data[24:27], "little") + 1
        h = int.from_bytes(data[27:30], "little") + 1
    elif chunk == b"VP8L" and data[20:21] == b"\x2f":
        (bits,) = struct.unpack("<I", data[21:25])
        w, h = (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1
    elif chunk == b"VP8 " and data[23:26] == b"\x9d\x01\x2a":
        w, h = struct.unpack("<HH", data[26:30])
        w, h = w & 0x3FFF, h & 0x3FFF
    else:
        return None
    return w, h, 4


def _tiff(data: bytes) -> tuple[int, int, int] | None:
    """The first image's width, length, samples per pixel and bits per sample."""
    order = "<" if data[:2] == b"II" else ">"
    (ifd,) = struct.unpack(order + "I", data[4:8])
    (count,) = struct.unpack(order + "H", data[ifd : ifd + 2])
    tags: dict[int, int] = {}
    for k in range(count):
        tag, kind, n, value = struct.unpack(order + "HHI4s", data[ifd + 2 + 12 * k :][:12])
        # SHORT values sit in the first two bytes of the field, LONG in all four; more
        # values than fit there are at the offset the field holds (the first one is kept).
        fmt = order + ("H" if kind == 3 else "I")
        if n * struct.calcsize(fmt) > 4:
            (at,) = struct.unpack(order + "I", value)
            value = data[at : at + 4]
        tags[tag] = struct.unpack(fmt, value[: struct.calcsize(fmt)])[0]
    if 256 not in tags or 257 not in tags:
        return None
    samples, bits = tags.get(277, 1), tags.get(258, 8)  # bits: of the first sample
    return tags[256], tags[257], max(samples, 1) * max(1, -(-bits // 8))


def decode_image(
    data: bytes,
    name: str,
    flags: int = -1,
    *,
    max_pixels: int = MAX_PIXELS,
    error: type[SoftarmError] = InputError,
) -> npt.NDArray[Any]:
    """The pixels of the encoded image ``data`` (``flags`` as ``cv2.imdecode``'s:
    -1 unchanged, 1 BGR, 0 grey), refused before decoding when its header claims more
    than ``max_pixels`` pixels or :data:`MAX_DECODED_BYTES`; ``name`` names it in the
    ``error`` raised."""
    import cv2

    header = image_header(data)
    if header is None:
        raise error(f"cannot read {name}: not a PNG, JPEG, BMP, TIFF or WebP image")
    w, h, per_pixel = header
    if w == 0 or h == 0:  # refused here: libpng would print its own warnings
        raise error(f"cannot read {name}: its header says {w} x {h} pixels")
    if w * h > max_pixels or w * h * per_pixel > MAX_DECODED_BYTES:
        raise error(
            f"cannot read {name}: {w} x {h} pixels of {per_pixel} bytes is larger than an image "
            f"may be ({max_pixels} pixels, {MAX_DECODED_BYTES} bytes)"
        )
    log = cv2.utils.logging
    level = log.getLogLevel()
    log.setLogLevel(log.LOG_LEVEL_SILENT)  # a broken file is our one line, not OpenCV's
    try:
        image = cv2.imdecode(np.frombuffer(data, dtype=np.uint8), flags)
    except cv2.error:
        image = None
    finally:
        log.setLogLevel(level)
    if image is None or image.size == 0:
        raise error(f"cannot read {name}: it does not decode as an image")
    return image


def read_image(
    path: str | Path,
    what: str,
    flags: int = -1,
    *,
    max_pixels: int = MAX_PIXELS,
    error: type[SoftarmError] = InputError,
) -> npt.NDArray[Any]:
    """The pixels of the image file ``path`` (see :func:`decode_image`); ``what`` names
    its role in the one-line ``error`` (a missing, special or oversized file too)."""
    data = read_image_bytes(path, what, error=error)
    return decode_image(data, f"{what} {str(path)!r}", flags, max_pixels=max_pixels, error=error)


def read_image_bytes(
    path: str | Path, what: str, *, error: type[SoftarmError] = InputError
) -> bytes:
    """The bytes of the image file ``path``: a regular file of at most
    :data:`MAX_FILE_BYTES` (else one line naming ``what`` and the file)."""
    name = f"{what} {str(path)!r}"
    with open_regular(path, what, error) as f:
        try:
            data = f.read(MAX_FILE_BYTES + 1)  # one byte past the bound: a file too large
        except OSError as exc:
            raise error(f"cannot read {name}: {exc.strerror or exc}") from None
    if len(data) > MAX_FILE_BYTES:
        raise error(f"cannot read {name}: larger than {MAX_FILE_BYTES} bytes")
    return data


def encode_image(image: npt.NDArray[Any], suffix: str = ".png") -> bytes:
    """``image`` encoded in the format of ``suffix`` (``cv2.imencode``)."""
    import cv2

    try:
        ok, buffer = cv2.imencode(suffix, np.asarray(image))
    except cv2.error:
        ok = False
    if not ok:
        shape = getattr(image, "shape", None)
        raise InputError(f"cannot encode an image of shape {shape} as {suffix}")
    data: bytes = buffer.tobytes()
    return data


def write_image(path: str | Path, image: npt.NDArray[Any], what: str = "image") -> None:
    """Encode ``image`` in the format of ``path``'s suffix and write it (in place: the
    recordings and data sets that write many images are built in a fresh folder).

    Raises:
        OutputError: the file cannot be written or the image encoded (one line).
    """
    try:
        data = encode_image(image, Path(path).suffix or ".png")
    except InputError as exc:
        raise OutputError(f"cannot write {what} {str(path)!r}: {exc}") from None
    target = check_target(path, what)  # a FIFO or a device is refused, not opened
    try:
        with open(target, "wb") as f:
            f.write(data)
    except OSError as exc:
        raise output_error(path, what, exc) from None
