"""A fitted curve is kept as a cane by its evidence (CaneSettings.evidence): its points
per metre and its radius, not its length alone."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.perception.cane_curves import CurveSearch
from softarm.perception.cane_evidence import CaneEvidence, curve_length, shows_a_cane
from softarm.perception.canes import CaneSettings, fit_cane_points

LENGTH_SEARCH = CurveSearch(min_support=20, support_length=0.08)


def _cane(length: float, n: int, radius: float, seed: int, offset: float = 0.0) -> np.ndarray:
    """(n, 4) centre-line points of a straight cane ``length`` (m) long, 1 mm noise,
    each with the cane's ``radius`` (m)."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, length, n))
    line = np.column_stack([0.3 + offset + 0.0 * t, 0.4 + 0.3 * t, 0.1 + t])
    line += rng.normal(0.0, 0.001, (n, 3))
    return np.column_stack([line, np.full(n, radius)])


def _fits(points: np.ndarray, evidence: CaneEvidence | None) -> int:
    settings = CaneSettings(max_points=8000, search=LENGTH_SEARCH, evidence=evidence)
    return len(fit_cane_points(points, settings))


def test_a_sparse_trail_is_dropped_a_cane_as_long_is_kept() -> None:
    trail = _cane(0.25, 75, 0.003, seed=1)  # 75 points over 26 cm: 290 a metre
    cane = _cane(0.25, 500, 0.003, seed=2, offset=0.2)  # 1,900 a metre
    assert _fits(trail, None) == 1 and _fits(cane, None) == 1  # the length alone passes both
    assert _fits(trail, CaneEvidence()) == 0
    assert _fits(cane, CaneEvidence()) == 1
    assert _fits(np.vstack([trail, cane]), CaneEvidence()) == 1


def test_a_curve_thinner_than_a_cane_is_dropped() -> None:
    thin = _cane(0.20, 400, 0.001, seed=3)  # a run 1–2 px wide: 1 mm at its depth
    assert _fits(thin, None) == 1
    assert _fits(thin, CaneEvidence()) == 0
    assert _fits(thin, CaneEvidence(min_radius=0.0005)) == 1


def test_shows_a_cane_counts_points_per_metre_of_the_curve() -> None:
    straight = np.array([[0.0, 0.1, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
    assert curve_length(straight) == pytest.approx(0.1)
    evidence = CaneEvidence(min_points=10, min_density=400.0, min_radius=0.002)
    assert shows_a_cane(40, straight, 0.003, evidence)  # 400 a metre
    assert not shows_a_cane(39, straight, 0.003, evidence)
    assert not shows_a_cane(9, straight, 0.003, CaneEvidence(min_points=10, min_density=0.0))
    assert not shows_a_cane(40, straight, 0.0019, evidence)


@pytest.mark.parametrize(
    ("field", "value"),
    [("min_points", 2.5), ("min_points", -1), ("min_density", float("nan")),
     ("min_radius", -0.001), ("min_density", "400"), ("min_points", True)],
)  # fmt: skip
def test_a_bad_threshold_is_one_error_naming_it(field: str, value: object) -> None:
    with pytest.raises(ParameterError, match=rf"evidence\.{field}"):
        CaneEvidence(**{field: value})  # type: ignore[arg-type]


def test_settings_refuse_evidence_that_is_not_a_cane_evidence() -> None:
    with pytest.raises(ParameterError, match=r"settings\.evidence"):
        CaneSettings(evidence={"min_points": 70})  # type: ignore[arg-type]
