"""The docs' table of cube tracking by approach angle (docs/perception.md, "Cube
tracking by approach angle, and the frustum"), from the figures that
``python -m softarm.experiments.cube_tracking ... --by-angle --into FILE`` gathers in
FILE (docs/data/perception/cube_tracking_by_angle.json: one entry per world and body,
keyed ``"<look or bush>/<body>"``):

    cd docs/data/perception
    python -m softarm.experiments.cube_tracking_table cube_tracking_by_angle.json
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

from softarm.errors import InputError

__all__ = ["merge_into", "table"]

_HEAD = (
    "| world | body | all: median / p95 mm (found) | consistent: median / p95 (n) "
    "| 0–40° | 40–50° | 50–60° | 60–70° | 70–90° | window px |\n"
    "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
)


def merge_into(path: Path, result: dict[str, Any]) -> None:
    """Put ``result`` (one run's figures with its ``seeds``, ``look`` and ``body``)
    into the JSON file ``path`` under ``"<look or bush>/<body>"``, keeping the other
    entries; a missing file is a new one.

    Raises:
        InputError: ``path`` holds no JSON object.
    """
    entries = _read(path) if path.exists() else {}
    entries[f"{result['look'] or 'bush'}/{result['body']}"] = result
    path.write_text(json.dumps(entries, indent=1) + "\n", encoding="utf-8")


def table(entries: dict[str, Any]) -> str:
    """The Markdown table of ``entries`` (see the module docstring), a row per entry in
    their order: median / p95 in mm with the poses found, "–" where none was."""
    rows = [_HEAD]
    for key, e in entries.items():
        world = "bush" if key.startswith("bush/") else f"row, {e['look']}"
        cells = [
            world,
            e["body"],
            f"{_pair(e['median_mm'], e['p95_mm'])} ({e['found']}/{e['poses']})",
            f"{_pair(e['median_consistent_mm'], e['p95_consistent_mm'])} ({e['consistent']})",
            *(f"{_pair(b['median_mm'], b['p95_mm'])} ({b['found']}/{b['poses']})"
              for b in e["by_angle"]),
            f"{e['mean_side_px']:.0f}",
        ]  # fmt: skip
        rows.append("| " + " | ".join(cells) + " |")
    return "\n".join(rows)


def _pair(median: float, p95: float) -> str:
    if math.isnan(median):
        return "–"
    return f"{median:.3f} / {p95:.2f}"


def _read(path: Path) -> dict[str, Any]:
    try:
        entries = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot read the cube tracking figures ({exc})") from exc
    if not isinstance(entries, dict):
        raise InputError(f"{path}: the cube tracking figures must be a JSON object")
    return entries


def main(argv: list[str] | None = None) -> int:
    """Print the table of the JSON file named in ``argv``; one line and 2 on error."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python -m softarm.experiments.cube_tracking_table FILE", file=sys.stderr)
        return 2
    try:
        print(table(_read(Path(args[0]))))
    except (InputError, KeyError, TypeError) as exc:
        print(f"error: {args[0]}: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
