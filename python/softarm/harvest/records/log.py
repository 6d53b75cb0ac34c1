"""A crash-safe JSON-lines log of the harvest loop.

Every control step appends one line and flushes it; every state transition and fault is
also ``fsync``'d, so after a crash (or a power cut on the robot) the file parses line by
line up to the last record written, and no transition is lost.

A power cut can still leave the last line cut off. A run that appends to such a file
first ends that line and writes a :data:`CUT_MARK` record, so its own records start on
a fresh line and :func:`read_log` knows the line above the mark was cut, not corrupt:
both runs stay readable.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterator, Mapping
from pathlib import Path
from types import TracebackType
from typing import IO, Any

import numpy as np

from softarm.errors import ConfigError, InputError
from softarm.files import check_document, check_target, open_regular, output_error

__all__ = ["CUT_MARK", "STEP_RENAMED", "HarvestLog", "current_record", "read_log"]

#: The kind of the record an appending run writes after a cut-off last line.
CUT_MARK = "previous_line_cut"
#: Longest line :func:`read_log` reads (1 MiB; a step record is a few hundred bytes): a
#: file without newlines must not be read whole into memory.
MAX_LINE_BYTES = 2**20
#: A ``step``'s fields renamed when they took their unit in their name (header format 2):
#: the old name -> the new. :func:`read_log` renames them in an older log.
STEP_RENAMED = {
    "target_age": "target_age_s",
    "position_error": "position_error_m",
    "orientation_error": "orientation_error_rad",
}


#: Significant digits of the floats in logs and reports: 10 nm on an elongation of a few
#: cm, 1 ms after 1000 s; the float noise beyond (2.7499999999999982 for 2.75) is gone.
DIGITS = 7


def _plain(value: Any) -> Any:
    """JSON-ready copy: arrays to lists, NaN/inf to None (strict JSON has no NaN), floats
    rounded to :data:`DIGITS` significant digits."""
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return _plain(value.item())
    if isinstance(value, float):
        return float(f"{value:.{DIGITS}g}") if math.isfinite(value) else None
    if hasattr(value, "value") and isinstance(value.value, str):  # str enums
        return value.value
    return value


class HarvestLog:
    """Appends records to ``path`` (None = keep them in memory only).

    ``records`` always holds everything written, for reports and tests.
    """

    def __init__(self, path: str | Path | None = None) -> None:
        self.path = None if path is None else Path(path)
        self.records: list[dict[str, Any]] = []
        self._file: IO[str] | None = None
        if self.path is not None:
            self._file = self._open(self.path)

    @staticmethod
    def _open(path: Path) -> IO[str]:
        """``path`` opened for appending; a cut-off last line is ended and marked first."""
        try:
            target = check_target(path, "log")
            target.parent.mkdir(parents=True, exist_ok=True)
            cut = _ends_cut(target)
            file = target.open("a", encoding="utf-8")
            if cut:
                file.write("\n" + json.dumps({"kind": CUT_MARK}) + "\n")
                file.flush()
                os.fsync(file.fileno())
        except OSError as exc:
            raise output_error(path, "log", exc) from None
        return file

    def step(self, **fields: Any) -> None:
        """One control step: written and flushed."""
        self._write({"kind": "step", **fields}, sync=False)

    def event(self, kind: str, **fields: Any) -> None:
        """A transition, fault or result: written, flushed and fsync'd."""
        self._write({"kind": kind, **fields}, sync=True)

    def _write(self, record: dict[str, Any], sync: bool) -> None:
        rec = _plain(record)
        self.records.append(rec)
        if self._file is None:
            return
        try:
            self._file.write(json.dumps(rec, allow_nan=False) + "\n")
            self._file.flush()
            if sync:
                os.fsync(self._file.fileno())
        except OSError as exc:
            raise output_error(self.path or "", "log", exc) from None

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` was called on a log written to a file."""
        return self._file is not None and self._file.closed

    def reopen(self) -> None:
        """Open the file again for appending after :meth:`close` (a stop recorded after
        the run closed its log); nothing for a log that is open or kept in memory."""
        if self.closed and self.path is not None:
            self._file = self._open(self.path)

    def close(self) -> None:
        """Sync and close the file. Calling it twice is harmless."""
        if self._file is not None and not self._file.closed:
            try:
                self._file.flush()
                os.fsync(self._file.fileno())
            except OSError as exc:
                raise output_error(self.path or "", "log", exc) from None
            finally:
                self._file.close()

    def __enter__(self) -> HarvestLog:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()


def _ends_cut(path: Path) -> bool:
    """Whether ``path`` exists, is not empty and its last byte is not a newline."""
    try:
        with path.open("rb") as f:
            if f.seek(0, os.SEEK_END) == 0:
                return False
            f.seek(-1, os.SEEK_END)
            return f.read(1) != b"\n"
    except FileNotFoundError:
        return False


def _lines(path: str | Path) -> Iterator[tuple[int, bytes]]:
    """(number, bytes) of each line of the regular file ``path``, without reading more
    than :data:`MAX_LINE_BYTES` for one line."""
    with open_regular(path, "log", InputError) as f:
        number = 0
        while line := f.readline(MAX_LINE_BYTES + 1):
            number += 1
            if len(line) > MAX_LINE_BYTES:
                raise InputError(f"{path}: line {number} is longer than {MAX_LINE_BYTES} bytes")
            yield number, line


def current_record(record: Any) -> Any:
    """``record`` with the field names of the current layout: a ``step`` of a log
    written before header format 2 has its fields renamed (:data:`STEP_RENAMED`), where
    the new name is not there already. Any other record is returned as it is."""
    if not isinstance(record, dict) or record.get("kind") != "step":
        return record
    if not any(old in record and new not in record for old, new in STEP_RENAMED.items()):
        return record
    return {
        STEP_RENAMED[k] if k in STEP_RENAMED and STEP_RENAMED[k] not in record else k: v
        for k, v in record.items()
    }


def read_log(path: str | Path) -> Iterator[dict[str, Any]]:
    """Records of a log file, in order, with the current field names
    (:func:`current_record`: an older log's ``step`` fields are renamed).

    A cut-off line (a crash mid-write) is skipped where it is the last line, or where the
    run appended after it marked it (:data:`CUT_MARK`). Any other malformed line is an
    :class:`~softarm.errors.InputError` naming the file and the line.
    """
    pending: InputError | None = None  # a bad line, kept until the next line tells
    ends_with_newline = True
    for number, line in _lines(path):
        record = _parse(path, number, line)
        marks_cut = isinstance(record, dict) and record.get("kind") == CUT_MARK
        if pending is not None and not marks_cut:
            raise pending
        pending = record if isinstance(record, InputError) else None
        if pending is None and line.strip():
            yield current_record(record)
        ends_with_newline = line.endswith(b"\n")
    if pending is not None and ends_with_newline:  # complete, so not cut: corrupt
        raise pending


def _parse(path: str | Path, number: int, line: bytes) -> Any:
    """The JSON value of ``line`` (None for a blank one), or the InputError refusing it
    (not UTF-8, not JSON, too deep, an integer past 64 bits)."""
    if not line.strip():
        return None
    where = f"{path}: line {number}"
    try:
        value = json.loads(line.decode("utf-8"))
        check_document(value, where)
    except json.JSONDecodeError as exc:
        return InputError(f"{where} is not a JSON record ({exc.msg})")
    except ConfigError as exc:
        return InputError(str(exc))
    except (UnicodeDecodeError, RecursionError, ValueError) as exc:
        return InputError(f"{where} is not a JSON record ({type(exc).__name__})")
    return value
