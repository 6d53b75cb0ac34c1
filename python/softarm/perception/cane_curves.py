"""Canes as cubic curves from 3D points: the planning paper's curve obstacle (eq. 10),
p(u) = Σ_k c_k u^k for u in [0, 1], fitted by least squares with u the normalised arc
length, and the points split into canes by sequential RANSAC (a line proposes a cane,
the cubic through its inliers grows it along the cane, past gaps where leaves hide it,
but not out to specks, stray points too sparse to be a glimpse of a cane);
then the pieces of one cane that a leaf cuts apart further than the growth reaches are
joined when their ends face each other and one cubic passes through both.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from softarm.checks import FloatArray

__all__ = ["CurveSearch", "arc_length_cubic", "curve_points", "split_into_curves"]

IndexArray = npt.NDArray[np.intp]

DEGREE = 3
DENSE = 200  # samples of a curve when points are matched to it
SCORED = 600  # points a proposed line is scored on
MAX_MISSES = 8  # proposed lines in a row that grow into no cane before the search ends
SUPPORT_BIN = 0.005  # m: the steps along a cane in which its support length is counted


@dataclass(frozen=True)
class CurveSearch:
    """How canes are found among 3D points (metres).

    line_tolerance: a point within this of a proposed line is its inlier.
    curve_tolerance: a point within this of a grown cubic belongs to that cane.
    min_support: fewest points a cane keeps (70: the phantoms that wrong stereo depths
        make are short runs of few points; on the tuning bushes 0–4, 40 → 70 took
        precision from 0.88 to 0.97 for coverage 0.85 → 0.83, and on diagnosis bush 708
        it removed the two phantoms that made the planner refuse two berries);
        min_length: its shortest extent.
    max_gap: the longest hole (a leaf in front) a cane is followed across.
    speck_radius, speck_points: a point with fewer than ``speck_points`` points
        (itself included, any point, not only its cane's) within ``speck_radius`` is a
        speck, a stray match, and no cane is grown across a hole to it: a cubic bent
        out to a few specks 5–12 cm away runs through open air, where the planner then
        sees a cane and may refuse a berry. Counted among all points with 4, not among
        the cane's with 5: C1's budget leaves a cane at 1 m about 300–500 points a
        metre, 6–10 within 1 cm, and the stereo scatters them across the cane, out of
        the curve's band; the old rule dropped so many true points that pieces of cane
        between leaves fell under ``min_support`` (on tuning renders 311000–311005 of
        the row in sun and overcast the fit lost 0.14–0.21 of the cane length its
        points reached; this rule covered 0.03–0.09 more of it at the same precision
        with either mask, the bush 0.03 more at 0.02 less: docs/perception.md "Where
        the row's canes are lost", with the fresh figures).
    specks_among_all: count a point's neighbours among all points (True, the default)
        or among its cane's alone (False, with 5 points: the rule before).
    proposals: random lines tried for each cane; seed: their generator's seed.
    join_gap, join_angle: two canes whose ends face each other across at most
        ``join_gap`` (m), each end's outward direction within ``join_angle`` (degrees)
        of the line to the other end, are one cane hidden in between when a single
        cubic passes 90 % of their points within ``curve_tolerance``.
    support_length: the length of cane (m) a cane's points must cover, counted in
        ``SUPPORT_BIN`` steps along it (a bin with any point counts): a support that
        means the same whatever the point budget, where ``min_support`` counts points
        and so depends on how many the budget keeps. 0: off, the count alone. 8 cm
        with 20 points and a budget of 8,000 (tuned on seeds 311000–311008 against 6,
        9, 10 and 12 cm) lost precision on fresh seeds (docs/perception.md): not the
        default.
    """

    line_tolerance: float = 0.008
    curve_tolerance: float = 0.006
    min_support: int = 70
    min_length: float = 0.04
    max_gap: float = 0.10
    speck_radius: float = 0.010
    speck_points: int = 4
    specks_among_all: bool = True
    proposals: int = 150
    seed: int = 0
    join_gap: float = 0.15
    join_angle: float = 35.0
    support_length: float = 0.0


def curve_points(coeffs: FloatArray, n: int = DENSE, u: FloatArray | None = None) -> FloatArray:
    """(n, 3) points of the curve ``coeffs`` (3, d+1), ascending powers, at even u in
    [0, 1] (or at the given ``u``)."""
    u = np.linspace(0.0, 1.0, n) if u is None else np.asarray(u, dtype=np.float64)
    return np.vander(u, coeffs.shape[1], increasing=True) @ coeffs.T


def arc_length_cubic(points: FloatArray, iterations: int = 3) -> FloatArray:
    """Coefficients (3, 4) of the cubic through ``points`` (n, 3) in u ∈ [0, 1], u the
    normalised arc length (planning paper eq. 10): start from each point's place along
    the principal axis, then alternately fit by least squares and re-place each point
    at its closest curve point, measured in arc length."""
    centred = points - points.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    t = centred @ axis
    u = (t - t.min()) / max(float(np.ptp(t)), 1e-12)
    coeffs = _least_squares(points, u)
    for _ in range(iterations):
        u = _arc_length_parameters(coeffs, points)
        coeffs = _least_squares(points, u)
    return coeffs


def _least_squares(points: FloatArray, u: FloatArray) -> FloatArray:
    vander = np.vander(u, DEGREE + 1, increasing=True)
    return cast(FloatArray, np.linalg.lstsq(vander, points, rcond=None)[0].T)


def _arc_length_parameters(coeffs: FloatArray, points: FloatArray) -> FloatArray:
    """Each point's closest place on the curve as normalised arc length, the curve
    trimmed to the span the points cover."""
    dense = curve_points(coeffs, DENSE)
    nearest = cKDTree(dense).query(points)[1]
    lo, hi = nearest.min(), nearest.max()
    steps = np.linalg.norm(np.diff(dense[lo : hi + 1], axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(steps)])
    result: FloatArray = arc[nearest - lo] / max(float(arc[-1]), 1e-12)
    return result


def split_into_curves(points: FloatArray, search: CurveSearch) -> list[IndexArray]:
    """Index arrays into ``points`` (n, 3), one per cane found. A proposed line that
    grows into no cane gives up its inliers (clutter, a leaf's edge), and the search
    ends after ``MAX_MISSES`` such lines in a row."""
    rng = np.random.default_rng(search.seed)
    remaining = np.arange(len(points))
    canes: list[IndexArray] = []
    misses = 0
    while len(remaining) >= search.min_support and misses < MAX_MISSES:
        line = _best_line(points[remaining], search, rng)
        if line is None:
            break
        members = _grow(points[remaining], line, search)
        misses = 0 if members is not None else misses + 1
        if members is not None:
            canes.append(remaining[members])
        remaining = np.delete(remaining, line if members is None else members)
    return _joined(points, canes, search)


def _joined(points: FloatArray, canes: list[IndexArray], search: CurveSearch) -> list[IndexArray]:
    """``canes`` with the pieces of one cane joined (see ``CurveSearch.join_gap``),
    the closest facing pair first, until no pair joins."""
    canes = list(canes)
    ends = [_ends(arc_length_cubic(points[c])) for c in canes]
    while True:
        best: tuple[float, int, int, IndexArray] | None = None
        for i in range(len(canes)):
            for j in range(i + 1, len(canes)):
                gap = _facing_gap(ends[i], ends[j], search)
                if gap is None or (best is not None and gap >= best[0]):
                    continue
                members = np.concatenate([canes[i], canes[j]])
                dense = curve_points(arc_length_cubic(points[members]), DENSE)
                residual = cKDTree(dense).query(points[members])[0]
                if np.percentile(residual, 90) <= search.curve_tolerance:
                    best = (gap, i, j, members)
        if best is None:
            return canes
        _, i, j, merged = best
        keep = [k for k in range(len(canes)) if k not in (i, j)]
        canes = [canes[k] for k in keep] + [merged]
        ends = [ends[k] for k in keep] + [_ends(arc_length_cubic(points[merged]))]


def _ends(coeffs: FloatArray) -> list[tuple[FloatArray, FloatArray]]:
    """The curve's two ends, each with the unit direction out of the curve there."""
    p = curve_points(coeffs, u=np.array([0.0, 0.05, 0.95, 1.0]))
    ends = []
    for end, inner in ((p[0], p[1]), (p[3], p[2])):
        out = end - inner
        ends.append((end, out / max(float(np.linalg.norm(out)), 1e-12)))
    return ends


def _facing_gap(
    a: list[tuple[FloatArray, FloatArray]],
    b: list[tuple[FloatArray, FloatArray]],
    search: CurveSearch,
) -> float | None:
    """The shortest gap (m), at most ``join_gap``, between an end of ``a`` and an end
    of ``b`` that face each other; None when no two do."""
    cos = float(np.cos(np.radians(search.join_angle)))
    best = None
    for pa, out_a in a:
        for pb, out_b in b:
            step = pb - pa
            gap = float(np.linalg.norm(step))
            if gap > search.join_gap or (best is not None and gap >= best):
                continue
            towards = step / max(gap, 1e-12)
            if gap < 1e-6 or (float(out_a @ towards) >= cos and float(-out_b @ towards) >= cos):
                best = gap
    return best


def _grow(points: FloatArray, line: IndexArray, search: CurveSearch) -> IndexArray | None:
    """The cane grown from the inliers ``line`` of a proposed line: alternately fit the
    cubic and take the points near it, in one run without long holes; None when it is
    too short or has too few points."""
    tree = cKDTree(points) if search.specks_among_all else None
    members = _longest_run(points, _without_specks(points, tree, line, search), search.max_gap)
    for _ in range(3):
        if len(members) < search.min_support:
            return None
        coeffs = arc_length_cubic(points[members])
        near = _near_curve(points, coeffs, search)
        members = _without_specks(points, tree, near, search)
        members = _longest_run(points, members, search.max_gap)
    if len(members) < search.min_support or _extent(points[members]) < search.min_length:
        return None
    if _covered_length(points[members]) < search.support_length:
        return None
    return members


def _best_line(
    points: FloatArray, search: CurveSearch, rng: np.random.Generator
) -> IndexArray | None:
    """Inlier indices of the random two-point line (points 2–10 cm apart) with most
    points within ``line_tolerance``, scored on a subsample of the points."""
    tree = cKDTree(points)
    scored = points[rng.permutation(len(points))[:SCORED]]
    best_direction, best_anchor, best_count = None, None, -1
    for a in rng.integers(0, len(points), search.proposals):
        near = np.asarray(tree.query_ball_point(points[a], 0.10), dtype=np.intp)
        far = near[np.linalg.norm(points[near] - points[a], axis=1) > 0.02]
        if far.size == 0:
            continue
        direction = points[far[rng.integers(0, far.size)]] - points[a]
        direction /= np.linalg.norm(direction)
        count = int(np.sum(_line_distance(scored, points[a], direction) < search.line_tolerance))
        if count > best_count:
            best_direction, best_anchor, best_count = direction, points[a], count
    if best_direction is None or best_anchor is None:
        return None
    distance = _line_distance(points, best_anchor, best_direction)
    return np.flatnonzero(distance < search.line_tolerance)


def _line_distance(points: FloatArray, anchor: FloatArray, direction: FloatArray) -> FloatArray:
    """Distance of each point to the line through ``anchor`` along unit ``direction``."""
    offset = points - anchor
    result: FloatArray = np.linalg.norm(offset - np.outer(offset @ direction, direction), axis=1)
    return result


def _near_curve(points: FloatArray, coeffs: FloatArray, search: CurveSearch) -> IndexArray:
    """Indices of points within ``curve_tolerance`` of the curve extended by max_gap
    at both ends (so that a cane grows past where its points stopped)."""
    length = float(np.sum(np.linalg.norm(np.diff(curve_points(coeffs), axis=0), axis=1)))
    reach = search.max_gap / max(length, 1e-9)
    dense = curve_points(coeffs, DENSE, np.linspace(-reach, 1.0 + reach, DENSE))
    distance = cKDTree(dense).query(points)[0]
    return np.flatnonzero(distance < search.curve_tolerance)


def _without_specks(
    points: FloatArray, tree: cKDTree | None, members: IndexArray, search: CurveSearch
) -> IndexArray:
    """The ``members`` that are not specks (see ``CurveSearch.speck_points``): their
    neighbours counted among all the points (``tree``, of ``points``), since the stereo
    scatters a sparse cane's points out of the curve's band (a stray match in open air
    has none either way); with ``tree`` None among the members alone."""
    if len(members) == 0:
        return members
    chosen = points[members]
    among = cKDTree(chosen) if tree is None else tree
    neighbours = among.query_ball_point(chosen, search.speck_radius, return_length=True)
    return members[np.asarray(neighbours) >= search.speck_points]


def _longest_run(points: FloatArray, members: IndexArray, max_gap: float) -> IndexArray:
    """The members along the principal axis, cut at holes longer than ``max_gap``;
    the run with most points."""
    if len(members) < 2:
        return members
    chosen = points[members]
    axis = np.linalg.svd(chosen - chosen.mean(axis=0), full_matrices=False)[2][0]
    order = np.argsort(chosen @ axis)
    t = (chosen @ axis)[order]
    cuts = np.flatnonzero(np.diff(t) > max_gap) + 1
    runs = np.split(order, cuts)
    return members[max(runs, key=len)]


def _covered_length(points: FloatArray) -> float:
    """The length (m) along the points' principal axis that they cover, in steps of
    ``SUPPORT_BIN``: a hole between them does not count, however many points crowd
    either side of it."""
    centred = points - points.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    bins = np.floor((centred @ axis) / SUPPORT_BIN).astype(np.int64)
    return float(np.unique(bins).size * SUPPORT_BIN)


def _extent(points: FloatArray) -> float:
    """Length of the points along their principal axis."""
    centred = points - points.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    return float(np.ptp(centred @ axis))
