"""The cube tracking's docs table (softarm.experiments.cube_tracking_table): drawn from
the JSON the runs gather, the one in docs/perception.md is the committed JSON's."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from softarm.errors import InputError
from softarm.experiments.cube_tracking_table import main, merge_into, table

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "data" / "perception" / "cube_tracking_by_angle.json"


def _result(look: str | None, body: str, median: float) -> dict[str, Any]:
    bins = [{"poses": 1, "found": 1, "median_mm": median, "p95_mm": median}] * 4
    bins.append({"poses": 1, "found": 0, "median_mm": math.nan, "p95_mm": math.nan})
    return {
        "seeds": [1], "look": look, "body": body, "poses": 5, "found": 4,
        "median_mm": median, "p95_mm": 2 * median, "consistent": 3,
        "median_consistent_mm": median, "p95_consistent_mm": median,
        "mean_side_px": 199.7, "by_angle": bins,
    }  # fmt: skip


def test_the_docs_table_is_the_committed_figures() -> None:
    docs = (ROOT / "docs" / "perception.md").read_text(encoding="utf-8").splitlines()
    for line in table(json.loads(FIGURES.read_text(encoding="utf-8"))).splitlines():
        assert line in docs, line


def test_runs_gather_in_one_file_by_world_and_body(tmp_path: Path) -> None:
    path = tmp_path / "figures.json"
    merge_into(path, _result(None, "cube", 0.1))
    merge_into(path, _result("sun", "frustum", 0.5))
    merge_into(path, _result(None, "cube", 0.2))  # a run again replaces its entry
    entries = json.loads(path.read_text(encoding="utf-8"))
    assert list(entries) == ["bush/cube", "sun/frustum"]
    rows = table(entries).splitlines()
    assert rows[2] == (
        "| bush | cube | 0.200 / 0.40 (4/5) | 0.200 / 0.20 (3) | 0.200 / 0.20 (1/1) "
        "| 0.200 / 0.20 (1/1) | 0.200 / 0.20 (1/1) | 0.200 / 0.20 (1/1) | – (0/1) | 200 |"
    )
    assert rows[3].startswith("| row, sun | frustum | 0.500 / 1.00 (4/5) |")


def test_a_file_that_is_no_figures_is_one_clear_error(tmp_path: Path, capsys: Any) -> None:
    path = tmp_path / "figures.json"
    path.write_text("[1, 2]", encoding="utf-8")
    with pytest.raises(InputError, match=r"figures\.json"):
        merge_into(path, _result(None, "cube", 0.1))
    assert main([str(path)]) == 2
    assert capsys.readouterr().err.count("\n") == 1
    assert main([]) == 2
