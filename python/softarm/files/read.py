"""The one reader of configuration and data files.

Every file goes through the same steps, each failure one
:class:`~softarm.errors.ConfigError` line naming the file: the path is a regular file
(a FIFO would block the open or the read for ever, ``/dev/zero`` would fill the memory),
its size is bounded, its bytes are UTF-8 without a byte-order mark, the text parses as
TOML or JSON, and the document's depth and integers are bounded
(:func:`~softarm.files.document.check_document`). The loaders then check each value
against its declared range (:mod:`softarm.files.ranges`).
"""

from __future__ import annotations

import codecs
import contextlib
import json
import os
import stat
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from softarm.errors import ConfigError, SoftarmError
from softarm.files.document import check_document

__all__ = [
    "MAX_BYTES",
    "load_json",
    "load_toml",
    "open_regular",
    "parse_json",
    "parse_toml",
    "read_text",
]

#: Largest configuration or data file read whole (16 MiB): a config is a few kB, an
#: id.json or camera file less; a bound keeps a wrong path from filling the memory.
MAX_BYTES = 16 * 2**20


def open_regular(path: str | Path, what: str, error: type[SoftarmError] = ConfigError) -> IO[bytes]:
    """``path`` opened for binary reading, after checking it is a regular file.

    The open itself does not block: ``O_NONBLOCK`` makes opening a FIFO with no writer
    return at once, and the file-type check then refuses it before any read.
    """
    name = str(path)
    try:
        fd = os.open(name, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        raise error(f"cannot read {what} {name!r}: no such file") from None
    except OSError as exc:
        raise error(f"cannot read {what} {name!r}: {exc.strerror or exc}") from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        kind = "a directory" if stat.S_ISDIR(mode) else "not a regular file"
        raise error(f"{what} {name!r} is {kind}")
    os.set_blocking(fd, True)
    return os.fdopen(fd, "rb")


def read_text(
    path: str | Path,
    what: str,
    *,
    max_bytes: int = MAX_BYTES,
    error: type[SoftarmError] = ConfigError,
) -> str:
    """The UTF-8 text of the regular file ``path`` of at most ``max_bytes`` bytes;
    ``what`` names the file's role in messages (``"config file"``, ``"id.json"``)."""
    name = str(path)
    with open_regular(path, what, error) as f:
        try:
            # One byte past the bound tells a file that grew after the check.
            data = f.read(max_bytes + 1)
        except OSError as exc:
            raise error(f"cannot read {what} {name!r}: {exc.strerror or exc}") from None
    if len(data) > max_bytes:
        raise error(f"{what} {name!r} is larger than {max_bytes} bytes")
    if data.startswith(codecs.BOM_UTF8):
        raise error(f"{what} {name!r} starts with a UTF-8 byte-order mark; save it without")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(
            f"{what} {name!r} is not UTF-8 (byte {data[exc.start]:#04x} at offset {exc.start})"
        ) from None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def parse_toml(text: str, source: str) -> dict[str, Any]:
    """The TOML document of ``text``, its depth and integers checked."""
    with _parse_errors(source, "TOML", tomllib.TOMLDecodeError):
        data = tomllib.loads(text)
    check_document(data, source)
    return data


def parse_json(text: str, source: str) -> Any:
    """The JSON document of ``text``, its depth and integers checked."""
    with _parse_errors(source, "JSON", json.JSONDecodeError):
        data = json.loads(text)
    check_document(data, source)
    return data


@contextlib.contextmanager
def _parse_errors(source: str, form: str, syntax: type[ValueError]) -> Iterator[None]:
    """A parser's failures as one ConfigError line naming ``source``: bad syntax, a
    document nested too deeply, an integer past Python's digit limit for str -> int."""
    try:
        yield
    except syntax as exc:
        raise ConfigError(f"{source}: not valid {form} ({_syntax_message(exc)})") from None
    except RecursionError:
        raise ConfigError(f"{source}: nested too deeply to parse") from None
    except ValueError as exc:
        raise ConfigError(f"{source}: a number is too long ({_first_line(exc)})") from None


def _syntax_message(exc: ValueError) -> str:
    if isinstance(exc, json.JSONDecodeError):
        return f"{exc.msg} at line {exc.lineno}"
    return _first_line(exc)


def load_toml(path: str | Path, what: str) -> dict[str, Any]:
    """Read and parse a TOML file (:func:`read_text`, :func:`parse_toml`)."""
    return parse_toml(read_text(path, what), str(path))


def load_json(path: str | Path, what: str) -> Any:
    """Read and parse a JSON file (:func:`read_text`, :func:`parse_json`)."""
    return parse_json(read_text(path, what), str(path))
