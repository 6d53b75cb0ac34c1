"""The markerless harvest's pooled figures (softarm.experiments.bush_harvest): the cane
coverage is pooled by each bush's cane length, the goal's measure."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from softarm.experiments.bush_harvest import summarise


def _report(
    coverage: float,
    length_m: float | None,
    canes: list[Any] | None = None,
    unmapped_shares: list[float] | None = None,
    precision: float | None = None,
) -> dict:
    cane_map: dict[str, Any] = {"median_mm": 1.0, "p95_mm": 3.0, "coverage": coverage}
    if length_m is not None:
        cane_map["length_m"] = length_m
    if precision is not None:
        cane_map["precision"] = precision
    return {
        "ripe_in_reach": 2, "ripe_harvested": 2, "ripe_never_mapped": 0, "unripe_picked": 0,
        "branch_contact_steps": 0, "sim_time_s": 4.0, "cane_map": cane_map,
        "berries": [{"harvested": True, "true_position_error_mm": 0.5}] * 2,
        "header": {"world": {"canes": canes or []}},
        **({} if unmapped_shares is None else {"ripe_never_mapped_c1_share": unmapped_shares}),
    }  # fmt: skip


def test_a_bush_weighs_by_its_cane_length() -> None:
    figures = summarise([_report(1.0, 1.0), _report(0.0, 3.0)])
    assert figures["cane_coverage"] == pytest.approx(0.25)
    assert figures["cane_coverage_per_bush"] == pytest.approx(0.5)


def test_an_older_report_takes_its_length_from_the_canes_its_header_records() -> None:
    # A straight cane 0.2 m long, inside the workspace: 0.2 m against 0.6 m given.
    cane = np.array([[0.0, 0.2, 0, 0], [0.3, 0, 0, 0], [0.2, 0, 0, 0]]).tolist()
    figures = summarise([_report(1.0, None, [cane]), _report(0.0, 0.6)])
    assert figures["cane_coverage"] == pytest.approx(0.25, abs=0.01)


def test_never_mapped_berries_under_a_tenth_in_view_count_as_hidden() -> None:
    figures = summarise([_report(1.0, 1.0, unmapped_shares=[0.0, 0.05, 0.6]),
                         _report(1.0, 1.0, unmapped_shares=[])])  # fmt: skip
    assert figures["never_mapped_hidden_from_c1"] == 2
    # A report that does not record the shares makes the count unknown, not 0.
    assert np.isnan(summarise([_report(1.0, 1.0)])["never_mapped_hidden_from_c1"])


def test_the_maps_precision_is_their_mean_and_unknown_when_a_report_lacks_it() -> None:
    both = [_report(1.0, 1.0, precision=0.8), _report(1.0, 1.0, precision=1.0)]
    assert summarise(both)["cane_precision"] == pytest.approx(0.9)
    assert np.isnan(summarise([*both, _report(1.0, 1.0)])["cane_precision"])


def test_a_folder_without_reports_is_one_clear_error(tmp_path: Path) -> None:
    from softarm.errors import InputError
    from softarm.experiments.bush_harvest import main

    with pytest.raises(InputError, match="no harvest reports"):
        main([str(tmp_path)])
    with pytest.raises(InputError, match="no harvest reports"):
        main([str(tmp_path / "absent")])
