"""softarm.simulate_harvest / softarm.harvest.simulate: the simulated harvest as one
documented call returning the report (issue 25 item 5)."""

from __future__ import annotations

import json
from pathlib import Path

import softarm
from softarm.harvest import HarvestReport, simulate


def test_simulate_returns_the_report_and_writes_a_replayable_log(tmp_path: Path) -> None:
    assert softarm.simulate_harvest is simulate and "simulate_harvest" in dir(softarm)
    assert "build_sim_rig" in (simulate.__doc__ or "")
    got = []
    log = tmp_path / "run.jsonl"
    report = softarm.simulate_harvest(
        berries=1, seed=0, log=log, on_berry=lambda i, r: got.append(i)
    )
    assert isinstance(report, HarvestReport) and len(report.berries) == 1 and got == [0]
    assert report.berries[0].harvested and report.success_rate == 1.0
    first = json.loads(log.read_text().splitlines()[0])
    assert first["kind"] == "header" and first["seed"] == 0 and first["berries"] == 1
    assert report.to_dict()["berries"][0]["true_position_error_mm"] is not None
