"""The results table of a sweep, streamed to disk as trials finish.

Each finished trial is written at once, atomically, as its own Parquet file under
``DIR/parts/`` (so a killed driver loses nothing that finished); ``DIR/results.parquet``
is the concatenation of the parts, rewritten atomically every few seconds and when the
sweep ends or is interrupted. ``--resume`` reads both: the parts, and the rows of
``results.parquet`` that have no part (a table copied without its parts still resumes).
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from softarm.sweep._deps import require

__all__ = ["ResultsTable", "results_schema"]

RESULTS = "results.parquet"
PARTS = "parts"

_BERRY_TYPES = {
    "berry": "int64",
    "tag_id": "int64",
    "harvested": "bool_",
    "true_position_error_mm": "float64",
    "orientation_error_deg": "float64",
    "true_orientation_error_deg": "float64",
    "position_error_mm": "float64",
    "duration_s": "float64",
    "fault": "string",
    "branch_contact_steps": "int64",
    "min_branch_gap_m": "float64",
    "stopped": "string",
    "berries_per_hour": "float64",
    "sim_s": "float64",
    "error": "string",
    "wall_s": "float64",
    "cpu_s": "float64",
    "node": "string",
}


def results_schema(plant: dict[str, tuple[Any, ...]]) -> Any:
    """The Arrow schema: ``trial_id``, ``seed``, one column per swept key (float, or
    string for a non-numeric key), then the per-berry columns of
    :data:`softarm.sweep.trial.BERRY_COLUMNS`."""
    pa = require("pyarrow")
    fields = [pa.field("trial_id", pa.string()), pa.field("seed", pa.int64())]
    for key, values in plant.items():
        numeric = all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)
        fields.append(pa.field(key, pa.float64() if numeric else pa.string()))
    fields += [pa.field(k, getattr(pa, t)()) for k, t in _BERRY_TYPES.items()]
    return pa.schema(fields)


class ResultsTable:
    """The streamed table of one sweep in ``out`` (see the module docstring)."""

    def __init__(
        self,
        out: str | Path,
        schema: Any,
        trial_ids: Iterable[str] | None = None,
        flush_every_s: float = 5.0,
    ) -> None:
        self.pa = require("pyarrow")
        self.pq = require("pyarrow.parquet")
        self.out = Path(out)
        self.parts = self.out / PARTS
        self.path = self.out / RESULTS
        self.schema = schema
        #: The trials ``results.parquet`` holds (those of the spec); None: every part.
        self.trial_ids = None if trial_ids is None else list(trial_ids)
        self.flush_every_s = flush_every_s
        self._last_flush = time.monotonic()
        self._dirty = False

    def exists(self) -> bool:
        """Whether a previous sweep left results here."""
        return self.path.exists() or (self.parts.is_dir() and any(self.parts.glob("*.parquet")))

    def _write(self, table: Any, path: Path) -> None:
        # Write beside the target, then rename: readers never see half a file. The
        # temporary name starts with "." so that dataset readers skip it.
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        self.pq.write_table(table, tmp)
        os.replace(tmp, path)

    def _table(self, rows: list[dict[str, Any]]) -> Any:
        return self.pa.Table.from_pylist(rows, schema=self.schema)

    def add(self, trial_id: str, rows: list[dict[str, Any]]) -> None:
        """Record one finished (or failed) trial; rewrites ``results.parquet`` when the last
        rewrite is older than ``flush_every_s``."""
        self.parts.mkdir(parents=True, exist_ok=True)
        self._write(self._table(rows), self.parts / f"{trial_id}.parquet")
        self._dirty = True
        if time.monotonic() - self._last_flush >= self.flush_every_s:
            self.flush()

    def _read_parts(self) -> dict[str, Any]:
        out = {}
        if self.parts.is_dir():
            for p in sorted(self.parts.glob("*.parquet")):
                out[p.stem] = self.pq.read_table(p)
        return out

    def adopt_results(self) -> None:
        """Give every trial of ``results.parquet`` that has no part file a part (resume)."""
        if not self.path.exists():
            return
        table = self.pq.read_table(self.path)
        have = set(self._read_parts())
        ids = table.column("trial_id").to_pylist()
        for trial_id in sorted(set(ids) - have):
            rows = [r for r in table.to_pylist() if r["trial_id"] == trial_id]
            self.parts.mkdir(parents=True, exist_ok=True)
            self._write(
                self.pa.Table.from_pylist(rows, schema=table.schema),
                self.parts / f"{trial_id}.parquet",
            )

    def finished(self) -> dict[str, bool]:
        """``trial_id`` → True if it ran, False if it is recorded as failed."""
        done = {}
        for trial_id, t in self._read_parts().items():
            errors = t.column("error").to_pylist() if "error" in t.column_names else [None]
            done[trial_id] = all(e is None for e in errors)
        return done

    def read(self, trial_ids: Iterable[str] | None = None) -> Any:
        """The rows of ``trial_ids`` (all parts when None) as one Arrow table."""
        parts = self._read_parts()
        keep = parts if trial_ids is None else {t: parts[t] for t in trial_ids if t in parts}
        if not keep:
            return self.schema.empty_table()
        return self.pa.concat_tables(list(keep.values()), promote_options="permissive")

    def flush(self) -> None:
        """Rewrite ``results.parquet`` from the parts of ``trial_ids`` (nothing to write
        before the first trial: an empty table would only block the next attempt)."""
        if not self.parts.is_dir() and not self.path.exists():
            return
        self.out.mkdir(parents=True, exist_ok=True)
        self._write(self.read(self.trial_ids), self.path)
        self._last_flush = time.monotonic()
        self._dirty = False
