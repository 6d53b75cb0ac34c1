"""A crash-safe JSON-lines log of the harvest loop.

Every control step appends one line and flushes it; every state transition and fault is
also ``fsync``'d, so after a crash (or a power cut on the robot) the file parses line by
line up to the last record written, and no transition is lost.
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

__all__ = ["HarvestLog", "read_log"]


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
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = self.path.open("a", encoding="utf-8")

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
        self._file.write(json.dumps(rec, allow_nan=False) + "\n")
        self._file.flush()
        if sync:
            os.fsync(self._file.fileno())

    def close(self) -> None:
        """Sync and close the file. Calling it twice is harmless."""
        if self._file is not None and not self._file.closed:
            self._file.flush()
            os.fsync(self._file.fileno())
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


def read_log(path: str | Path) -> Iterator[dict[str, Any]]:
    """Records of a log file, in order. A truncated last line (a crash mid-write) is
    skipped; any other malformed line raises ``json.JSONDecodeError``."""
    lines = Path(path).read_text(encoding="utf-8").split("\n")
    for i, line in enumerate(lines):
        if not line:
            continue
        try:
            yield json.loads(line)
        except json.JSONDecodeError:
            if i == len(lines) - 1:  # no newline after it: the write was cut short
                return
            raise
