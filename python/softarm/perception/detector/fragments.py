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

Each heatmap kind has its rule (:data:`FRAGMENT_RULES`); the logistic heatmap's broad
peaks do not fall between touching fruit, so it has none."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

__all__ = ["FRAGMENT_RULES", "FragmentRule", "merge_fragments", "speck", "without_rules"]

_Mask = npt.NDArray[np.bool_]
_F32 = npt.NDArray[np.float32]


@dataclass(frozen=True)
class FragmentRule:
    """When two pieces of a split are one fruit, and when a piece is no fruit.

    ``saddle``: two neighbouring pieces are merged when the heatmap between their peaks
    stays at least this share of the lower peak (None: never merged).
    ``speck_pixels``, ``speck_peak``: a piece of fewer network pixels than
    ``speck_pixels`` whose heatmap maximum is under ``speck_peak`` is dropped (0: none)."""

    saddle: float | None
    speck_pixels: int = 0
    speck_peak: float = 0.0


#: The rule of each heatmap kind (``NetworkOutput.heatmap``); a kind not named has none.
#: The focal one's values were chosen on validation renders (dataset seed 100300, sun,
#: overcast and dusk, 20 images each), never on the evaluation sets: docs/perception.md.
FRAGMENT_RULES: dict[str, FragmentRule] = {
    "focal": FragmentRule(saddle=0.7, speck_pixels=20, speck_peak=0.3),
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
