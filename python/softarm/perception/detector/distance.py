"""Touching fruit apart by the predicted distance to each fruit's edge
(``softarm detector train --distance``): the "deep watershed" of Bai and Urtasun (2017).

Such a network gives each fruit pixel its distance to the edge of its own fruit divided
by that fruit's largest such distance: 1 at a fruit's centre, near 0 at its edge, and the
same for a fruit of 4 px as for one of 40 (a scale-free target, unlike a band of fixed
width: :mod:`.boundary`). Two touching fruit then show two hills with a valley at their
contact, where the target of each is near 0, however small either is. A part of the
fruit mask is split by markers, the connected regions of the predicted distance above
DISTANCE_LEVEL inside it (one per hill), and a marker-based watershed on the negated
distance (each pixel goes to the marker whose hill it climbs to, the basins meeting in
the valleys: Meyer's flooding, by levels of the distance: :func:`flood`): one piece per
marker, the whole part where there are fewer than two.
"""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np
import numpy.typing as npt
from scipy import ndimage

__all__ = ["DISTANCE_LEVEL", "FLOOD_STEP", "MIN_MARKER", "distance_pieces", "flood", "markers"]

#: A marker is a connected region of the predicted distance above this (the upper half of
#: each fruit's hill; the trained network's hills reach 0.6-0.7, not 1). This,
#: MIN_MARKER and DROP_HILLLESS were chosen on the validation renders only (dataset seed
#: 100300, sun, overcast, dusk, 20 images each): levels 0.35-0.45 kept more fruit pieces
#: that are no fruit (precision with both checks down to 0.87-0.95), 0.55 lost a fifth to
#: a quarter of the ripe fruit found at 0.5 (hills that stay under it).
DISTANCE_LEVEL = 0.5
#: Fewest pixels of a marker (network px): a smaller one is a bump of a hill, not a fruit
#: (1 and 4 kept more false pieces; 8 and 12 lost small fruit).
MIN_MARKER = 6
#: Whether a part with no marker (no hill of MIN_MARKER pixels above DISTANCE_LEVEL) is
#: dropped as no fruit, else kept whole: dropping them raised precision in every look
#: of the validation renders (a fruit-coloured patch the network calls fruit without
#: the shape of one) at the same or nearly the same ripe recall.
DROP_HILLLESS = True
#: The flooding's levels of the distance, from DISTANCE_LEVEL down to 0.
FLOOD_STEP = 0.05
_EIGHT = np.ones((3, 3), bool)


def markers(
    part: npt.NDArray[np.bool_], distance: npt.NDArray[np.float32]
) -> tuple[int, npt.NDArray[np.int32]]:
    """The count and label map (0 off a marker) of the markers of ``part`` (a boolean
    mask) in ``distance`` (its window of the network's map): the 8-connected regions of
    the part where the distance exceeds DISTANCE_LEVEL, those under MIN_MARKER pixels
    left out."""
    labels, n = ndimage.label(part & (distance > DISTANCE_LEVEL), structure=_EIGHT)
    if n and MIN_MARKER > 1:
        sizes = np.bincount(labels.ravel(), minlength=n + 1)
        keep = sizes >= MIN_MARKER
        keep[0] = False
        relabel = np.zeros(n + 1, np.int32)
        relabel[keep] = np.arange(1, int(keep.sum()) + 1)
        labels, n = relabel[labels], int(keep.sum())
    return int(n), cast(npt.NDArray[np.int32], labels.astype(np.int32))


def distance_pieces(
    part: npt.NDArray[np.bool_], distance: npt.NDArray[np.float32]
) -> list[npt.NDArray[np.bool_]]:
    """``part`` as one mask per marker (:func:`markers`), each pixel to the marker whose
    basin of the negated ``distance`` it lies in; ``[part]`` when it has one, and when it
    has none unless DROP_HILLLESS (then no piece)."""
    n, labels = markers(part, distance)
    if n == 0 and DROP_HILLLESS:
        return []
    if n < 2:
        return [part]
    basins = flood(part, distance, labels)
    return [part & (basins == k) for k in range(1, n + 1)]


def flood(
    part: npt.NDArray[np.bool_], distance: npt.NDArray[np.float32], labels: npt.NDArray[np.int32]
) -> npt.NDArray[np.int32]:
    """The markers ``labels`` flooded over ``part`` downhill in ``distance``, by levels of
    FLOOD_STEP: at each level every marker grows, a pixel at a time (8-connected), over
    the part's pixels at or above it, until none grows. Where two basins reach a pixel in
    the same step the higher label takes it. (scipy's ``watershed_ift`` is not this
    flooding: it gave most of a small fruit's pixels to its large neighbour.)"""
    grown = labels.astype(np.float32)
    kernel = np.ones((3, 3), np.uint8)
    d = np.where(part, distance, -1.0)
    for level in [*np.arange(DISTANCE_LEVEL, 0.0, -FLOOD_STEP).tolist(), -0.5]:
        allowed = (d >= level) & (grown == 0)
        while allowed.any():
            reach = cv2.dilate(grown, kernel)
            new = allowed & (reach > 0)
            if not new.any():
                break
            grown[new] = reach[new]
            allowed &= ~new
    return cast(npt.NDArray[np.int32], grown.astype(np.int32))
