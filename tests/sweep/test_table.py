"""The results table: parts written as trials finish, results.parquet rebuilt from them,
resume from a table alone, failed trials known; summaries of the rows."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pyarrow")
import pyarrow.parquet as pq

from softarm.sweep import parse_spec
from softarm.sweep.summary import axis_label, group_stats, markdown_summary, plot_summary
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
    # 4 berries in 2 x 2 s (seed 0) + 2 x 3 s (seed 1) of simulated time: 1440 an hour.
    assert stats[(0.08,)].berries_per_hour == pytest.approx(3600 * 4 / 10)
    text = markdown_summary(all_rows, ["pressure_tau"])
    assert "## By pressure_tau" in text and "| 0.3 | 2 | 100.0 % |" in text
    assert "berries / h" in text and "| 1440 |" in text
    plot_summary(all_rows, ["pressure_tau"], tmp_path / "summary.png")
    assert (tmp_path / "summary.png").stat().st_size > 10_000


def test_the_summary_plot_axes_carry_units(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib.pyplot as plt

    kept: list[Any] = []
    monkeypatch.setattr(plt, "close", kept.append)
    trials = SPEC.trials()
    plot_summary([r for t in trials for r in rows(t)], ["pressure_tau"], tmp_path / "s.png")
    (fig,) = kept
    labels = [ax.get_ylabel() for ax in fig.axes if ax.get_ylabel()]
    assert labels == ["harvested (%)", "mean true error (mm)", "median s / berry (sim.)"]
    assert fig.axes[-1].get_xlabel() == "pressure_tau (s)"
    assert axis_label("twist_spread") == "twist_spread (rad)"
    assert axis_label("gain_spread") == "gain_spread (relative)"
    assert axis_label("cutoff") == "cutoff (rad/s)"
    assert axis_label("hysteresis_psi") == "hysteresis_psi"  # the name says it
    assert axis_label("model") == "model" and axis_label("seed") == "seed"


def test_one_of_a_count_is_singular(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 25 item 6 ("1 berries"): the sweep figure's title and the tune file's header."""
    import matplotlib.pyplot as plt

    from softarm.sweep.tune import _header

    kept: list[Any] = []
    monkeypatch.setattr(plt, "close", kept.append)
    one = parse_spec({"sweep": {"seeds": [0], "berries": 1}})
    plot_summary(rows(one.trials()[0]), [], tmp_path / "s.png")
    assert kept[0]._suptitle.get_text() == "softarm sweep: 1 berry, other keys pooled"
    metrics = {"score": 1.0, "success": 1.0, "cycle_s": 2.0, "mean_error_mm": 0.5}
    text = _header(one, 1, metrics, None)
    assert ": 1 candidate, Optuna TPE" in text and "1 berry per bush" in text
