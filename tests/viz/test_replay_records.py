"""Issue 26 item 7: a malformed replay record is an InputError naming it, and a record's
kind reaches only the drawing methods of an explicit table."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("rerun")

from softarm.errors import InputError
from softarm.viz.replay import replay


@pytest.mark.parametrize(
    "record",
    [
        {"kind": "step", "t": 0.0, "state": [1]},
        {"kind": "plan", "t": 0.0, "q": 5},
        {"kind": "berry_result", "t": 0.0, "true_position_error_mm": "far"},
        {"kind": "step", "t": True},
    ],
)
def test_malformed_record_is_one_input_error(tmp_path, record) -> None:
    log = tmp_path / "bad.jsonl"
    log.write_text(json.dumps(record) + "\n")
    with pytest.raises(InputError, match=r"bad\.jsonl: (record|line) 1") as err:
        replay(log, tmp_path / "bad.rrd")
    assert "\n" not in str(err.value)


def test_a_400_digit_time_is_refused_with_its_line(tmp_path) -> None:
    log = tmp_path / "bad.jsonl"
    log.write_text('{"kind": "step", "t": ' + "9" * 400 + "}\n")
    with pytest.raises(InputError, match=r"bad\.jsonl: line 1"):
        replay(log, tmp_path / "bad.rrd")


@pytest.mark.parametrize("kind", ["results", "arm", "text", "draw_result_berries", "log"])
def test_a_kind_naming_an_attribute_is_drawn_as_text(tmp_path, kind) -> None:
    log = tmp_path / "odd.jsonl"
    log.write_text(json.dumps({"kind": kind, "t": 0.0, "value": 1}) + "\n")
    assert replay(log, tmp_path / "odd.rrd") == 1
