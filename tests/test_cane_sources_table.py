"""The cane sources' table (softarm.experiments.cane_sources): rows pooled per condition,
source and point budget, the two budgets side by side; no rendering."""

from __future__ import annotations

from typing import Any

import pytest

from softarm.experiments.cane_sources import side_by_side, summarise


def _row(seed: int, budget: str | None, coverage: float, length: float) -> dict[str, Any]:
    row: dict[str, Any] = {
        "condition": "sun", "source": "net", "seed": seed, "length_m": length,
        "coverage": coverage, "fitted_m": 1.0, "precision": 0.9, "median_mm": 2.0,
        "fits": 3, "fit_ms": 100.0 * seed,
    }  # fmt: skip
    if budget is not None:
        row["budget"] = budget
    return row


def test_coverage_is_pooled_by_length_per_budget() -> None:
    rows = [_row(1, "view", 0.2, 1.0), _row(2, "view", 0.5, 3.0), _row(1, "reach", 0.8, 1.0)]
    by_budget = {r["budget"]: r for r in summarise(rows)}
    assert by_budget["view"]["coverage"] == pytest.approx((0.2 + 1.5) / 4.0, abs=1e-3)
    assert by_budget["view"]["scenes"] == 2 and by_budget["view"]["fit_ms"] == 150.0
    assert by_budget["reach"]["coverage"] == 0.8 and by_budget["reach"]["seeds"] == [1, 1]


def test_rows_written_before_the_reach_count_as_the_whole_views_budget() -> None:
    (only,) = summarise([_row(1, None, 0.3, 1.0)])
    assert only["budget"] == "view"


def test_the_side_by_side_table_gives_each_figure_before_and_after() -> None:
    lines = side_by_side(summarise([_row(1, "view", 0.2, 1.0), _row(1, "reach", 0.8, 1.0)]))
    assert lines[2].startswith("| sun | `net` | 1/1 | 0.2 → 0.8 | 0.9 → 0.9 |")


def test_the_reach_budget_keeps_the_count_support_the_length_budget_the_defaults() -> None:
    from dataclasses import replace

    from softarm.experiments.cane_sources import BUDGETS
    from softarm.perception.canes import CaneSettings

    assert BUDGETS["reach"].max_points == 4000 and BUDGETS["reach"].search.min_support == 70
    assert BUDGETS["reach"].search.support_length == 0.0
    assert BUDGETS["view"].reach is None and BUDGETS["reach"] == CaneSettings()
    # ``before``: the default before the specks were counted among all points
    old = replace(CaneSettings().search, speck_points=5, specks_among_all=False)
    assert BUDGETS["before"] == replace(CaneSettings(), search=old)
    assert BUDGETS["length"].search.support_length == 0.08


def test_the_kept_fits_are_pooled_as_every_fit_and_missing_figures_are_dashes() -> None:
    row = _row(1, "reach", 0.8, 1.0)
    row.update(kept_coverage=0.5, kept_precision=1.0, kept_median_mm=1.5, kept_fitted_m=0.5)
    (summary,) = summarise([row])
    assert summary["kept_coverage"] == 0.5 and summary["kept_precision"] == 1.0
    lines = side_by_side(summarise([_row(1, "view", 0.2, 1.0), row]))
    assert "| - → 1.0 |" in lines[2]
