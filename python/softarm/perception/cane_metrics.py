"""How well a cane map matches the true canes (issue 23's goal: median distance to the
true centre line ≤ 5 mm over at least 90 % of the cane length in the arm's workspace).

Each true centre line is sampled every millimetre of its length; the samples outside
the workspace are dropped. For each sample, the distance to the nearest fitted curve
(any fit, each drawn densely over u ∈ [0, 1]):

- ``coverage``: the share of the true cane length (in the workspace) whose distance is
  at most ``covered_within`` (10 mm by default: twice the goal, a cane radius plus the
  gripper's margin; a part farther from every fit counts as missed);
- ``median_mm``, ``p95_mm``: median and 95th percentile of the distance over the
  covered samples (what the map says where it says something);
- ``median_all_mm``: the median over all samples, missed ones included;
- ``precision``: the share of fitted curve length (in the workspace) within
  ``covered_within`` of a true centre line: phantom canes lower it;
- ``length_m``: the true cane length scored.

Both sides are centre lines, so a perfect map scores 0 whatever the cane radius.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
from scipy.spatial import cKDTree

from softarm.checks import FloatArray
from softarm.perception.cane_curves import curve_points

__all__ = ["DEFAULT_REACH", "cane_map_error"]

DEFAULT_REACH = 0.6  # m from the base origin: the default workspace
SPACING = 0.001  # m between samples of a centre line

Workspace = float | tuple[FloatArray, FloatArray] | None


class _Curve(Protocol):
    """A cubic cane: a CaneFit, or the sim's Branch."""

    @property
    def coeffs(self) -> FloatArray: ...


def cane_map_error(
    fits: Sequence[_Curve],
    true_branches: Sequence[_Curve],
    workspace: Workspace = None,
    covered_within: float = 0.010,
) -> dict[str, float]:
    """Scores of ``fits`` (anything with ``coeffs`` (3, d+1): CaneFit) against
    ``true_branches`` (anything with ``coeffs``: sim Branch); see the module docstring.

    ``workspace``: a radius (m) about the base origin, or a box (lower (3,), upper
    (3,)) in the base frame; None is a ``DEFAULT_REACH`` radius. With no true cane in
    the workspace, coverage is 1 and the distances 0; with no fit, coverage is 0 and
    the distances NaN."""
    truth = _inside(_sampled([b.coeffs for b in true_branches]), workspace)
    fitted = _inside(_sampled([f.coeffs for f in fits]), workspace)
    if len(truth) == 0:
        return _scores(
            np.zeros(1), np.ones(1, bool), _precision(fitted, truth, covered_within), 0.0
        )
    if len(fitted) == 0:
        return _scores(
            np.full(len(truth), np.inf), np.zeros(len(truth), bool), 0.0, len(truth) * SPACING
        )
    distance = cKDTree(fitted).query(truth)[0]
    covered = distance <= covered_within
    precision = _precision(fitted, truth, covered_within)
    return _scores(distance, covered, precision, len(truth) * SPACING)


def _sampled(all_coeffs: Sequence[FloatArray]) -> FloatArray:
    """Points every ``SPACING`` along each curve, stacked (n, 3)."""
    parts = [np.zeros((0, 3))]
    for coeffs in all_coeffs:
        coarse = curve_points(np.asarray(coeffs, dtype=np.float64), 200)
        length = float(np.sum(np.linalg.norm(np.diff(coarse, axis=0), axis=1)))
        n = max(2, int(np.ceil(length / SPACING)) + 1)
        parts.append(curve_points(np.asarray(coeffs, dtype=np.float64), n))
    return np.vstack(parts)


def _inside(points: FloatArray, workspace: Workspace) -> FloatArray:
    if workspace is None or np.isscalar(workspace):
        reach = DEFAULT_REACH if workspace is None else float(workspace)  # type: ignore[arg-type]
        result: FloatArray = points[np.linalg.norm(points, axis=1) <= reach]
        return result
    lower, upper = (np.asarray(b, dtype=np.float64) for b in workspace)  # type: ignore[union-attr]
    return points[np.all((points >= lower) & (points <= upper), axis=1)]


def _precision(fitted: FloatArray, truth: FloatArray, within: float) -> float:
    if len(fitted) == 0:
        return 1.0
    if len(truth) == 0:
        return 0.0
    return float(np.mean(cKDTree(truth).query(fitted)[0] <= within))


def _scores(
    distance: FloatArray, covered: FloatArray, precision: float, length: float
) -> dict[str, float]:
    kept = distance[covered] * 1000.0
    return {
        "median_mm": float(np.median(kept)) if kept.size else float("nan"),
        "p95_mm": float(np.percentile(kept, 95)) if kept.size else float("nan"),
        "median_all_mm": float(np.median(distance) * 1000.0),
        "coverage": float(np.mean(covered)),
        "precision": precision,
        "length_m": length,
    }
