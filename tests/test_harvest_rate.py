"""Issue 40 item 4: the harvest rate, berries per hour of simulated time, and its
breakdown by stage, read from the run log's transitions; `softarm harvest` prints it and
the report carries it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from softarm.cli import main
from softarm.harvest.records.rate import rate_line, rate_record, state_seconds
from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.rig import build_sim_rig


def _transition(t: float, old: str, new: str) -> dict[str, object]:
    return {"kind": "transition", "t": t, "berry": 1, "old": old, "new": new, "why": ""}


RECORDS = [
    {"kind": "step", "t": 0.1},
    _transition(0.5, "idle", "initial_placement"),
    _transition(1.5, "initial_placement", "fine_positioning"),
    {"kind": "event", "t": 2.0},
    _transition(2.25, "fine_positioning", "grasp"),
    _transition(2.5, "grasp", "return_home"),
    _transition(3.5, "return_home", "done"),
]


def test_state_seconds_are_the_gaps_between_transitions() -> None:
    assert state_seconds(RECORDS) == {
        "initial_placement": 1.0,
        "fine_positioning": 0.75,
        "grasp": 0.25,
        "return_home": 1.0,
    }


def test_the_stages_and_the_rest_add_up_to_the_run() -> None:
    rate = rate_record(RECORDS, harvested=1, total_s=4.0)
    assert rate["berries_per_hour"] == pytest.approx(900.0)
    assert rate["s_per_berry"] == pytest.approx(4.0)
    assert rate["stage_s"] == {
        "survey": 0.0,
        "placement": 1.0,
        "fine_positioning": 0.75,
        "grasp": 0.25,
        "home": 1.0,
        "other": pytest.approx(1.0),  # 0.5 s before the first transition, 0.5 s after the last
    }
    assert rate_line(rate) == (
        "rate: 900 berries/h simulated, 4.00 s per berry (survey 0.00, placement 1.00, "
        "fine positioning 0.75, grasp 0.25, home 1.00, other 1.00 s)"
    )


def test_a_run_without_a_harvested_berry_has_no_time_per_berry() -> None:
    rate = rate_record(RECORDS, harvested=0, total_s=4.0)
    assert rate["berries_per_hour"] == 0.0 and rate["s_per_berry"] is None
    assert rate_line(rate) == "rate: 0 berries/h (4.0 s simulated, none harvested)"


def test_a_tag_world_harvest_reports_its_rate() -> None:
    rig = build_sim_rig(SimRigOptions(n_berries=2, seed=4))
    report = rig.run()
    rate = report.extra["rate"]
    total = report.extra["sim_time_s"]
    assert report.harvested == 2
    assert rate["berries_per_hour"] == pytest.approx(3600.0 * 2 / total)
    assert sum(rate["stage_s"].values()) == pytest.approx(total)
    for stage in ("placement", "fine_positioning", "home"):
        assert rate["stage_s"][stage] > 0.0, stage
    # Every berry's own clock time (IDLE to its end) is spent in the stages.
    assert sum(b.duration_s for b in report.berries) <= total + 1e-9


def test_softarm_harvest_prints_and_saves_the_rate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    report = tmp_path / "report.json"
    assert main(["harvest", "--sim", "--berries", "1", "--seed", "4", "--report", str(report)]) == 0
    out = capsys.readouterr().out
    (line,) = [x for x in out.splitlines() if x.startswith("rate: ")]
    saved = json.loads(report.read_text())["rate"]
    assert f"{saved['berries_per_hour']:.0f} berries/h simulated" in line
    assert "placement" in line and "fine positioning" in line and "home" in line
