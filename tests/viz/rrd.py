"""Reading a rerun recording back with the SDK, for the tests: rows per entity."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import Any


def read_rrd(path: Path) -> dict[str, list[dict[str, Any]]]:
    """Every row of the recording at ``path`` as ``{entity path: [{column: value}]}``,
    in the order the SDK stores them; raises if the file is not a readable recording."""
    from rerun.chunk import RrdReader

    rows: dict[str, list[dict[str, Any]]] = defaultdict(list)
    reader = RrdReader(path)
    assert reader.recordings(), f"{path} holds no recording"
    for chunk in reader.stream():
        batch = chunk.to_record_batch().to_pylist()
        rows[chunk.entity_path].extend(batch)
    return dict(rows)


def sim_seconds(row: dict[str, Any]) -> float:
    """The row's time on the ``sim_time`` timeline, in seconds."""
    return row["sim_time"].total_seconds()


def column(
    rows: dict[str, list[dict[str, Any]]], entity: str, name: str
) -> list[tuple[float, Any]]:
    """``(sim seconds, value)`` of the component column ``name`` (e.g. ``Scalars:scalars``)
    of ``entity``, in time order; static rows (no time) are left out."""
    out = [
        (sim_seconds(r), r[name])
        for r in rows.get(entity, [])
        if r.get(name) is not None and r.get("sim_time") is not None
    ]
    return sorted(out, key=lambda item: item[0])
