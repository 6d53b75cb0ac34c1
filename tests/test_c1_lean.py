"""The C1 lean trace's summary (softarm.experiments.c1_lean): an error's share along
the sun's image direction is positive towards the sun, and the berries counted as
leaning away from it are those whose share is negative."""

from __future__ import annotations

from typing import Any

import pytest

from softarm.experiments.c1_lean import seed_range, summary


def _row(left: list[float], sun: list[float]) -> dict[str, Any]:
    return {
        "left": left, "ray": left, "outline": [0.0, 0.0], "sun": sun,
        "approach": [1.0, 0.0], "off_axis_px": [0.0, 10.0], "perspective_px": 0.01,
    }  # fmt: skip


def test_a_lean_away_from_the_sun_is_negative_along_it() -> None:
    rows = [
        _row([0.0, 0.3], [0.0, -1.0]),
        _row([0.0, 0.1], [0.0, -1.0]),
        _row([-0.2, 0.0], [1.0, 0.0]),
    ]
    s = summary(rows)
    assert s["berries"] == 3
    assert s["left"]["away_from_sun"] == 3
    assert s["left"]["along_sun_median_px"] == pytest.approx(-0.2)
    assert s["left"]["median_px"] == pytest.approx(0.2)
    assert s["ray"]["outward_median_px"] == pytest.approx(0.1)  # +y: away from the axis
    assert s["outline"]["away_from_sun"] == 0


def test_no_berries_summarise_to_a_count() -> None:
    assert summary([]) == {"berries": 0}


def test_seed_ranges_include_both_ends() -> None:
    assert seed_range("1500-1502") == [1500, 1501, 1502]
    assert seed_range("7") == [7]
