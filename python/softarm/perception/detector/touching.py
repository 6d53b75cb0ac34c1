"""Fruit that touch, told apart by the shape of their blob alone: a fruit's outline is
a disc (or the visible part of one), so the distance from each of a blob's pixels to
its edge (the distance map) peaks once per fruit, at its centre, at the fruit's radius.
Two discs of radius r whose centres lie d apart join through a neck whose half-width,
the distance map's saddle on the line between the centres, is sqrt(r² - d²/4): 0 where
they just touch, r·sqrt(1 - (d / 2r)²) as they overlap. A peak is a fruit of its own
when the saddle between it and every larger peak of the blob is below NECK of its own
height (the lower of the two radii); otherwise it is a bump of the larger fruit's
outline (a drupelet, a ragged edge), whose saddle is the bump's own height. With NECK
0.75 two equal fruit are told apart from a centre spacing of 1.32 r (a third of a
fruit's width hidden behind the other), and one elongated fruit, whose distance map has
one peak, never is. Each pixel then goes to the fruit whose outline it lies deepest in:
the seed k with the least |p - c_k| - r_k (the additively weighted nearest seed), which
for two touching discs divides them at the point of contact, where the plain nearest
seed would cut the larger one at the midpoint of the centres.

None of this reads the network's centre heatmap or any threshold of it: the network's
instances (:mod:`.instances`) and the colour rule's blobs
(:mod:`softarm.perception.berries`) use it alike."""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

__all__ = ["NECK", "Seed", "disc_seeds", "split_discs"]

#: A peak of the distance map is a fruit of its own when the saddle between it and each
#: larger peak is below this share of its own height (the geometry above; the value
#: chosen on the validation renders, dataset seed 100300).
NECK = 0.75
#: The most peaks of one blob looked at (the highest): a blob of a cluster holds a few
#: fruit, and the pairwise saddle test costs the square of the peaks.
MAX_PEAKS = 64
#: (row, col, radius): a fruit's centre in the blob's mask and the distance map there.
Seed = tuple[float, float, float]
_F32 = npt.NDArray[np.float32]


def _distance(mask: npt.NDArray[np.bool_]) -> _F32:
    """The distance (px) of each pixel of ``mask`` to the nearest pixel outside it, the
    mask's own border counting as outside."""
    padded = np.pad(mask, 1).astype(np.uint8)
    dist = cv2.distanceTransform(padded, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
    # The exact Euclidean distance is the root of an integer; OpenCV's float differs in
    # its last bit from call to call (with the buffer's alignment), which flipped ties
    # between neighbours, and so peaks, from one run to the next. Rounded to that
    # integer first, the map is the same every time.
    squared = np.rint(dist.astype(np.float64) ** 2)
    return cast(_F32, np.sqrt(squared).astype(np.float32))


def _saddle(dist: _F32, a: tuple[int, int], b: tuple[int, int]) -> float:
    """The lowest distance on the straight line from ``a`` to ``b`` (both ends included):
    for two discs, the neck between their centres."""
    n = int(np.ceil(np.hypot(a[0] - b[0], a[1] - b[1]))) + 1
    t = np.arange(n) / max(n - 1, 1)
    rows = np.rint(a[0] + t * (b[0] - a[0])).astype(np.intp)
    cols = np.rint(a[1] + t * (b[1] - a[1])).astype(np.intp)
    return float(dist[rows, cols].min())


def _second_fruit(
    dist: _F32, peak: tuple[int, int], kept: list[tuple[int, int]], neck: float
) -> bool:
    """Whether ``peak`` is a fruit apart from every ``kept`` (higher) one. A peak inside
    a kept one's inscribed disc is that fruit's without a look at the saddle: two fruit
    told apart lie more than 2 r sqrt(1 - NECK²) (1.32 r) apart, beyond r."""
    height = float(dist[peak])
    for k in kept:
        if (peak[0] - k[0]) ** 2 + (peak[1] - k[1]) ** 2 < float(dist[k]) ** 2:
            return False
    return all(_saddle(dist, peak, k) < neck * height for k in kept)


def disc_seeds(mask: npt.NDArray[np.bool_], min_radius: float, neck: float = NECK) -> list[Seed]:
    """The fruit centres of a blob ``mask`` (bool (h, w)): the peaks of its distance map
    of at least ``min_radius`` px that the saddle test keeps, highest first; at least the
    highest peak whatever its height, none for an empty mask."""
    dist = _distance(mask)
    grown = cv2.dilate(dist, np.ones((3, 3), np.uint8))
    rows, cols = np.nonzero((dist >= grown) & (dist > 0))
    if rows.size == 0:
        return []
    order = np.argsort(-dist[rows, cols], kind="stable")[:MAX_PEAKS]
    kept: list[tuple[int, int]] = []
    for r, c in zip(rows[order].tolist(), cols[order].tolist(), strict=True):
        if kept and float(dist[r, c]) < min_radius:
            break  # the rest are lower still
        if _second_fruit(dist, (r, c), kept, neck):
            kept.append((r, c))
    return [(float(r), float(c), float(dist[r, c])) for r, c in kept]


def split_discs(mask: npt.NDArray[np.bool_], seeds: list[Seed]) -> list[npt.NDArray[np.bool_]]:
    """``mask`` divided between ``seeds``: each pixel to the seed whose disc it lies
    deepest in (least distance to the centre less the radius); the mask itself for
    fewer than two seeds."""
    if len(seeds) < 2:
        return [mask]
    rows, cols = np.nonzero(mask)
    # One pass per seed with a running least (memory of the blob's size, not times the
    # seeds: a frame-wide dark blob holds MAX_PEAKS of them).
    best = np.full(rows.size, np.inf)
    owner = np.zeros(rows.size, np.intp)
    for k, (r, c, radius) in enumerate(seeds):
        reach = np.hypot(rows - r, cols - c) - radius
        closer = reach < best
        best[closer], owner[closer] = reach[closer], k
    out = []
    for k in range(len(seeds)):
        piece = np.zeros_like(mask)
        piece[rows[owner == k], cols[owner == k]] = True
        out.append(piece)
    return out
