"""The canes' support as a length of cane (CurveSearch.support_length): the same cane
found whatever the point density, a short dense run refused however many points it has."""

from __future__ import annotations

import numpy as np

from softarm.perception.cane_curves import CurveSearch, split_into_curves
from softarm.perception.canes import even_subsample


def _straight(length: float, n: int, seed: int, start: float = 0.0) -> np.ndarray:
    """``n`` points along a straight cane ``length`` (m) long, 1 mm noise."""
    rng = np.random.default_rng(seed)
    t = start + rng.uniform(0.0, length, n)
    line = np.column_stack([t, 0.5 + 0.2 * t, 0.3 + 0.1 * t])
    return line + rng.normal(0.0, 0.001, (n, 3))


def test_a_short_dense_run_is_refused_however_many_points_it_has() -> None:
    run = _straight(0.05, 2000, seed=1)  # 5 cm: a phantom's length, 2000 points
    assert split_into_curves(run, CurveSearch(min_support=20, support_length=0.08)) == []
    # counted in points it passes: the count depends on the budget, not on the cane
    assert len(split_into_curves(run, CurveSearch(min_support=70, support_length=0.0))) == 1


def test_a_cane_is_found_at_any_density_when_support_is_a_length() -> None:
    cane = _straight(0.20, 4000, seed=2)
    search = CurveSearch(min_support=20, support_length=0.08)
    for budget in (4000, 400, 60):
        assert len(split_into_curves(even_subsample(cane, budget), search)) == 1
    # a count of 70 loses the same cane once the budget thins it below 70 points
    assert (
        split_into_curves(even_subsample(cane, 60), CurveSearch(min_support=70, support_length=0.0))
        == []
    )


def test_a_hole_does_not_count_towards_the_length() -> None:
    # two 4 cm pieces 8 cm apart: a cane 16 cm long end to end, 8 cm of it covered
    pieces = np.vstack([_straight(0.04, 400, 3), _straight(0.04, 400, 4, start=0.12)])
    assert split_into_curves(pieces, CurveSearch(min_support=20, support_length=0.10)) == []
    assert len(split_into_curves(pieces, CurveSearch(min_support=20, support_length=0.07))) == 1


def test_even_subsample_keeps_at_most_the_budget_evenly() -> None:
    points = np.arange(40.0).reshape(10, 4)
    assert np.array_equal(even_subsample(points, 5), points[::2])
    assert len(even_subsample(points, 3)) == 3 and len(even_subsample(points, 100)) == 10
