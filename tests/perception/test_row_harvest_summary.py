"""The row's harvest through softarm.experiments.bush_harvest: the row's reports pooled as
the bush's, the p95 true error and the smallest cane gap, the row's command line."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from softarm.errors import InputError
from softarm.experiments.bush_harvest import main, summarise


def _report(errors: list[float], gap_m: float, contacts: int = 0) -> dict[str, Any]:
    return {
        "world": "row", "ripe_in_reach": len(errors), "ripe_harvested": len(errors),
        "ripe_never_mapped": 0, "unripe_picked": 0, "branch_contact_steps": contacts,
        "min_branch_gap_m": gap_m, "sim_time_s": 4.0,
        "cane_map": {"median_mm": 1.0, "p95_mm": 3.0, "coverage": 0.5, "length_m": 1.0},
        "berries": [{"harvested": True, "true_position_error_mm": e} for e in errors],
    }  # fmt: skip


def test_p95_error_smallest_gap_and_runs_with_contact() -> None:
    errors = [float(e) for e in range(1, 21)]  # 1..20 mm
    figures = summarise([_report(errors[:10], 0.03), _report(errors[10:], -0.0178, 6)])
    assert figures["p95_true_fine_error_mm"] == pytest.approx(19.05)
    assert figures["min_cane_gap_mm"] == pytest.approx(-17.8)
    assert figures["contact_steps"] == 6 and figures["runs_with_contact"] == 1


def test_row_reports_are_pooled(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "r90120.json").write_text(json.dumps(_report([1.0, 2.0], 0.04)))
    main([str(tmp_path)])
    line = capsys.readouterr().out
    assert '"ripe_in_reach": 2' in line and '"min_cane_gap_mm": 40.0' in line


def test_run_takes_the_row_and_its_look(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    calls: list[list[str]] = []

    def fake_run(command: list[str], **_: Any) -> None:
        calls.append(command)
        Path(command[command.index("--report") + 1]).write_text(json.dumps(_report([1.0], 0.02)))

    monkeypatch.setattr("softarm.experiments.bush_harvest.subprocess.run", fake_run)
    out = tmp_path / "sun"
    main(["--run", "5", "5", str(out), "-", "--world", "row", "--look", "sun", "--berries", "4"])
    assert len(calls) == 1  # "-": no tag world
    assert calls[0][calls[0].index("--world") + 1 :][:3] == ["row", "--look", "sun"]
    assert calls[0][calls[0].index("--berries") + 1] == "4"
    assert (out / "wall_times.txt").read_text().startswith("5 wall ")


def test_run_refuses_a_look_without_the_row(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="--look"):
        main(["--run", "5", "5", str(tmp_path), "-", "--look", "sun"])
    with pytest.raises(InputError, match="--look"):
        main(["--run", "5", "5", str(tmp_path), "-", "--world", "row"])
