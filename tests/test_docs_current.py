"""The generated tables of the docs are current: what ``make docs`` writes from the code
that measures it, the code still gives. Timings vary from run to run and machine to
machine, so only the deterministic columns are compared (iterations, reached, clearance,
collision)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from softarm.planning.report import TITLES
from softarm.planning.scenarios import SCENARIOS, compare

ROOT = Path(__file__).resolve().parents[1]
PLANNING = (ROOT / "docs" / "planning.md").read_text(encoding="utf-8")


def documented_rows(name: str) -> dict[str, tuple[str, str, str, str]]:
    """{method: (iterations, reached, clearance, collision)} of the scenario's table."""
    section = PLANNING.split(f"## {TITLES[name]}\n", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 6 and re.fullmatch(r"\d+", cells[1]):
            rows[cells[0]] = (cells[1], cells[3], cells[4], cells[5])
    return rows


@pytest.mark.parametrize("name", SCENARIOS)
def test_planning_tables_are_current(name: str) -> None:
    documented = documented_rows(name)
    assert documented, f"no table for {name!r} in docs/planning.md"
    for r in compare(name, repeats=1):
        now = (
            str(r.iterations),
            "yes" if r.reached else "no",
            f"{r.min_clearance:.4f}",
            "**yes**" if r.collision else "no",
        )
        assert documented.get(r.method) == now, (
            f"docs/planning.md is stale for {name}/{r.method}: documented "
            f"{documented.get(r.method)}, the code gives {now}; run `make docs`"
        )
