"""The JSON-lines log survives a crash: every record up to the last parses."""

from __future__ import annotations

import json

import pytest

from softarm.errors import InputError
from softarm.harvest import BerryTarget, HarvestLog, read_log
from softarm.harvest.records.header import UNITS
from softarm.harvest.records.log import current_record
from softarm.harvest.runs.policy import run_targets

from .fakes import make_rig


def test_crash_mid_run_vents_and_leaves_a_complete_log(tmp_path) -> None:
    path = tmp_path / "run.jsonl"
    rig = make_rig(HarvestLog(path))
    rig.tracker.crash_after = 1.0
    with pytest.raises(RuntimeError, match="simulated bug"):
        run_targets(rig.machine.run_berry, [BerryTarget(1)], rig.machine.log)
    # No close(): the process "died" here. Every line written so far must parse.
    lines = path.read_text().splitlines()
    records = [json.loads(line) for line in lines]
    assert len(records) == len(rig.machine.log.records)
    assert records[-1]["kind"] == "crash"
    assert sum(r["kind"] == "step" for r in records) > 10
    assert records == rig.machine.log.records  # nothing lost, nothing extra
    transitions = [r["new"] for r in records if r["kind"] == "transition"]
    assert transitions[:2] == ["idle", "initial_placement"] and "done" not in transitions
    assert rig.vented()


def test_step_records_hold_the_documented_fields(tmp_path) -> None:
    rig = make_rig(HarvestLog(tmp_path / "run.jsonl"))
    run_targets(rig.machine.run_berry, [BerryTarget(1)], rig.machine.log)
    rig.machine.log.close()
    steps = [r for r in read_log(tmp_path / "run.jsonl") if r["kind"] == "step"]
    placing = [r for r in steps if r["state"] == "initial_placement"]
    assert placing
    keys = ("t", "q", "pose", "target", "goal", "camera", "saturated")
    for key in (*keys, "target_age_s", "position_error_m", "orientation_error_rad"):
        assert key in placing[0]
    assert set(UNITS["step"]) <= set(placing[0])  # the header documents every unit
    assert len(placing[0]["q"]) == 3 and len(placing[0]["pose"]) == 4


def test_read_log_renames_the_step_fields_of_an_older_log(tmp_path) -> None:
    old = {"kind": "step", "t": 0.5, "target_age": 0.1, "position_error": 0.002,
           "orientation_error": 0.05, "goal": None}  # fmt: skip
    path = tmp_path / "format1.jsonl"
    path.write_text(json.dumps(old) + "\n" + json.dumps({"kind": "fault", "t": 0.6}) + "\n")
    step, fault = read_log(path)
    assert step == {"kind": "step", "t": 0.5, "target_age_s": 0.1, "position_error_m": 0.002,
                    "orientation_error_rad": 0.05, "goal": None}  # fmt: skip
    assert fault == {"kind": "fault", "t": 0.6}
    assert current_record(step) is step  # a current record is left as it is
    both = {"kind": "step", "position_error": 1.0, "position_error_m": 2.0}
    assert current_record(both) == both  # the new name wins; nothing is overwritten


def test_read_log_skips_only_a_truncated_last_line(tmp_path) -> None:
    path = tmp_path / "cut.jsonl"
    path.write_text('{"kind": "step", "t": 0.0}\n{"kind": "step", "t": 0.05}\n{"kind": "st')
    assert [r["t"] for r in read_log(path)] == [0.0, 0.05]
    path.write_text('{"kind": "step"}\n{"kind": \n{"kind": "step"}\n')
    with pytest.raises(InputError, match=r"cut\.jsonl: line 2 is not a JSON record"):
        list(read_log(path))


def test_nan_is_written_as_null(tmp_path) -> None:
    log = HarvestLog(tmp_path / "nan.jsonl")
    log.event("x", value=float("nan"))
    log.close()
    assert next(read_log(tmp_path / "nan.jsonl"))["value"] is None
