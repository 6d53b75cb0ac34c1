"""The results table: parts written as trials finish, results.parquet rebuilt from them,
resume from a table alone, failed trials known; summaries of the rows."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pyarrow")
import pyarrow.parquet as pq

from softarm.sweep import parse_spec
from softarm.sweep.summary import group_stats, markdown_summary, plot_summary
from softarm.sweep.table import ResultsTable, results_schema
from softarm.sweep.trial import error_row

from .fakes import rows

SPEC = parse_spec(
    {"sweep": {"seeds": [0, 1], "berries": 2, "plant": {"pressure_tau": [0.08, 0.3]}}}
)


def _table(out: Path) -> ResultsTable:
    trials = SPEC.trials()
    return ResultsTable(out, results_schema(SPEC.plant), [t.trial_id for t in trials])


def test_rows_stream_to_parts_and_the_table(tmp_path: Path) -> None:
    table = _table(tmp_path)
    assert not table.exists()
    t0, t1 = SPEC.trials()[:2]
    table.add(t0.trial_id, rows(t0))
    assert (tmp_path / "parts" / f"{t0.trial_id}.parquet").exists()  # durable at once
    table.add(t1.trial_id, [error_row(t1, "RuntimeError: boom")])
    table.flush()
    got = pq.read_table(tmp_path / "results.parquet")
    assert got.num_rows == 3
    assert set(got.column_names) >= {
        "seed", "pressure_tau", "harvested", "true_position_error_mm", "orientation_error_deg",
        "duration_s", "fault", "branch_contact_steps", "min_branch_gap_m", "error",
    }  # fmt: skip
    assert table.finished() == {t0.trial_id: True, t1.trial_id: False}
    assert not list(tmp_path.rglob(".*tmp"))  # no temporary file left behind


def test_nothing_finished_leaves_no_table(tmp_path: Path) -> None:
    # A sweep stopped before its first trial must not block the next attempt.
    table = _table(tmp_path)
    table.flush()
    assert not table.exists() and not (tmp_path / "results.parquet").exists()


def test_a_table_without_its_parts_resumes(tmp_path: Path) -> None:
    table = _table(tmp_path)
    t0, t1 = SPEC.trials()[:2]
    table.add(t0.trial_id, rows(t0))
    table.add(t1.trial_id, rows(t1))
    table.flush()
    for p in (tmp_path / "parts").iterdir():
        p.unlink()
    again = _table(tmp_path)
    again.adopt_results()
    assert again.finished() == {t0.trial_id: True, t1.trial_id: True}
    assert again.read().num_rows == 4


def test_summary_tables_and_plot(tmp_path: Path) -> None:
    trials = SPEC.trials()
    all_rows = [r for t in trials[:3] for r in rows(t)] + [error_row(trials[3], "boom")]
    stats = group_stats(all_rows, ["pressure_tau"])
    assert stats[(0.08,)].berries == 4 and stats[(0.08,)].harvested == 1.0
    assert stats[(0.3,)].berries == 2 and stats[(0.3,)].failed_trials == 1
    assert stats[(0.08,)].median_duration_s == pytest.approx(2.5)
    text = markdown_summary(all_rows, ["pressure_tau"])
    assert "## By pressure_tau" in text and "| 0.3 | 2 | 100.0 % |" in text
    plot_summary(all_rows, ["pressure_tau"], tmp_path / "summary.png")
    assert (tmp_path / "summary.png").stat().st_size > 10_000
