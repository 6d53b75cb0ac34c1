"""Fragments of one fruit after the centre heatmap's split (:mod:`.instances`), told
from fruit of their own.

A focal-loss heatmap (``softarm detector train --heatmap focal``) is trained to be 1 at
each fruit's centre and 0 everywhere else, so between the peaks of two fruit that touch
it falls to nearly nothing: the fruit's contact is a negative of the loss. Where it
gives one fruit two peaks (a turning fruit, red on one side and black on the other, or
a fruit seen through a gap in the leaves), it stays high between them: the two peaks
are one bump with two tops. So two neighbouring pieces of a split are merged back when
the heatmap, along the straight line between their peaks, never falls below
:attr:`FragmentRule.saddle` of the lower peak. The shape of the pieces says nothing
here: the split's gain is in clusters whose outline shows no neck between the fruit,
and the same test on the outline (:mod:`.touching`'s) merged about ten pairs of
different fruit for each fragment on the validation renders.

A piece that is small and weak, fewer than :attr:`FragmentRule.speck_pixels` network
pixels with a heatmap peak under :attr:`FragmentRule.speck_peak`, is dropped: the core
of a shaded fruit that the network only half saw, or a speck on a dark leaf, where a
fruit of that size has a clear peak of its own.

A piece that is small but kept, fewer than :attr:`FragmentRule.grow_pixels`, is grown
by up to :attr:`FragmentRule.grow_px` network pixels into the pixels around it that the
network calls fruit with at least :attr:`FragmentRule.grow_low` (under the fruit
threshold, so no other part's): on the validation renders most of the focal network's
remaining false detections were no fragments but the cores of fruit it half saw (green
fruit in the bush, dark fruit at dusk), a fifth to a third of the fruit's area, too
little to match it, whose rim the network still gave a third or more.

Each heatmap kind has its rule (:data:`FRAGMENT_RULES`); the logistic heatmap's broad
peaks do not fall between touching fruit, so it has none."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

__all__ = ["FRAGMENT_RULES", "FragmentRule", "grown", "merge_fragments", "speck", "without_rules"]

_Mask = npt.NDArray[np.bool_]
_F32 = npt.NDArray[np.float32]


@dataclass(frozen=True)
class FragmentRule:
    """When two pieces of a split are one fruit, and when a piece is no fruit.

    ``saddle``: two neighbouring pieces are merged when the heatmap between their peaks
    stays at least this share of the lower peak (None: never merged).
    ``speck_pixels``, ``speck_peak``: a piece of fewer network pixels than
    ``speck_pixels`` whose heatmap maximum is under ``speck_peak`` is dropped (0: none).
    ``grow_pixels``, ``grow_low``, ``grow_px``: a piece of fewer pixels than
    ``grow_pixels`` is grown by up to ``grow_px`` pixels into free pixels whose fruit
    probability is at least ``grow_low`` (0: none)."""

    saddle: float | None
    speck_pixels: int = 0
    speck_peak: float = 0.0
    grow_pixels: int = 0
    grow_low: float = 1.0
    grow_px: int = 0


#: The rule of each heatmap kind (``NetworkOutput.heatmap``); a kind not named has none.
#: The focal one's values were chosen on validation renders (dataset seed 100300, sun,
#: overcast and dusk, 20 images each), never on the evaluation sets: docs/perception.md.
FRAGMENT_RULES: dict[str, FragmentRule] = {
    "focal": FragmentRule(
        saddle=0.7, speck_pixels=20, speck_peak=0.3, grow_pixels=30, grow_low=0.35, grow_px=2
    ),
}


def _line_minimum(values: _F32, a: tuple[int, int], b: tuple[int, int]) -> float:
    """The least of ``values`` on the straight line from ``a`` to ``b`` (both included)."""
    n = int(np.ceil(np.hypot(a[0] - b[0], a[1] - b[1]))) + 1
    t = np.arange(n) / max(n - 1, 1)
    rows = np.rint(a[0] + t * (b[0] - a[0])).astype(np.intp)
    cols = np.rint(a[1] + t * (b[1] - a[1])).astype(np.intp)
    return float(values[rows, cols].min())


def _touch(a: _Mask, b: _Mask) -> bool:
    """Whether ``b`` has a pixel among ``a``'s eight neighbours."""
    grown = cv2.dilate(a.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    return bool((grown & b).any())


def _root(parent: list[int], k: int) -> int:
    while parent[k] != k:
        parent[k] = parent[parent[k]]
        k = parent[k]
    return k


def merge_fragments(
    pieces: list[_Mask],
    peaks: list[tuple[int, int]],
    centres: _F32,
    rule: FragmentRule | None,
) -> list[_Mask]:
    """``pieces`` (one per peak of ``peaks``, (row, col) in ``centres``, the heatmap over
    the same window) with every two neighbours that ``rule`` calls one fruit joined; in
    the order of their first piece. Unchanged without a rule or with fewer than two."""
    if rule is None or rule.saddle is None or len(pieces) < 2 or len(peaks) != len(pieces):
        return pieces
    parent = list(range(len(pieces)))
    for i in range(len(pieces)):
        for j in range(i + 1, len(pieces)):
            low = min(float(centres[peaks[i]]), float(centres[peaks[j]]))
            if _line_minimum(centres, peaks[i], peaks[j]) < rule.saddle * low:
                continue  # the heatmap falls between them: two fruit
            if _touch(pieces[i], pieces[j]):
                parent[_root(parent, j)] = _root(parent, i)
    groups: dict[int, _Mask] = {}
    for k, piece in enumerate(pieces):
        root = _root(parent, k)
        groups[root] = piece.copy() if root not in groups else groups[root] | piece
    return list(groups.values())


def speck(piece: _Mask, centres: _F32, rule: FragmentRule | None) -> bool:
    """Whether ``piece`` (over the window of ``centres``) is too small and too weak to be
    a fruit by ``rule``."""
    if rule is None or rule.speck_pixels <= 0:
        return False
    if int(np.count_nonzero(piece)) >= rule.speck_pixels:
        return False
    return float(centres[piece].max(initial=0.0)) < rule.speck_peak


def grown(
    piece: _Mask, x: int, y: int, fruit: _F32, taken: _Mask, rule: FragmentRule | None
) -> tuple[_Mask, int, int]:
    """``piece`` (over a window whose corner is (``x``, ``y``) in the network's map) and
    that corner, grown by ``rule`` into the pixels of ``fruit`` (the whole map's fruit
    probability) that no part holds (``taken``: the map's fruit pixels); as it is when
    ``rule`` does not grow it."""
    if rule is None or rule.grow_px <= 0 or int(np.count_nonzero(piece)) >= rule.grow_pixels:
        return piece, x, y
    h, w = piece.shape
    k = rule.grow_px
    x0, y0 = max(x - k, 0), max(y - k, 0)
    x1, y1 = min(x + w + k, fruit.shape[1]), min(y + h + k, fruit.shape[0])
    mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
    mask[y - y0 : y - y0 + h, x - x0 : x - x0 + w] = piece
    free = (fruit[y0:y1, x0:x1] >= rule.grow_low) & ~taken[y0:y1, x0:x1]
    for _ in range(k):  # one ring at a time, so it grows only through free pixels
        ring = cv2.dilate(mask, np.ones((3, 3), np.uint8)) > 0
        mask[ring & free] = 1
    return mask > 0, x0, y0


@contextmanager
def without_rules() -> Iterator[None]:
    """Within the block, no heatmap kind has a fragment rule (the decoding as it was
    before this module): for measuring what the rule changes, one thread at a time."""
    saved = dict(FRAGMENT_RULES)
    FRAGMENT_RULES.clear()
    try:
        yield
    finally:
        FRAGMENT_RULES.update(saved)
