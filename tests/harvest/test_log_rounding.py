"""Logs and reports carry floats rounded to 7 significant digits, not float noise."""

from __future__ import annotations

import numpy as np

from softarm.harvest import HarvestLog, read_log
from softarm.harvest.records.report import BerryResult


def test_log_and_report_floats_are_rounded(tmp_path) -> None:
    path = tmp_path / "log.jsonl"
    with HarvestLog(path) as log:
        log.step(t=2.7499999999999982, q=np.array([0.012837922313492296, 0.0]), ok=True)
    text = path.read_text()
    assert "2.7499999999999982" not in text and "0.012837922313492296" not in text
    (record,) = read_log(path)
    assert record["t"] == 2.75 and record["q"] == [0.01283792, 0.0] and record["ok"] is True
    result = BerryResult(10, duration_s=0.1 + 0.2, position_error_mm=float("nan"))
    d = result.to_dict()
    assert d["duration_s"] == 0.3 and d["position_error_mm"] is None
