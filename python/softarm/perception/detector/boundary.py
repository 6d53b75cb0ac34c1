"""Touching fruit apart by the boundary class (``softarm detector train --boundary``).

Such a network marks the pixels of a fruit that lie against another fruit (a band of
about two of its pixels on each side of the contact). The fruit pixels it marks
(probability above BOUNDARY_THRESHOLD) are taken out of the fruit mask before it is
split into connected parts, so that a cluster the fruit mask draws as one blob falls
apart at its contacts; each removed pixel is then given back to the nearest remaining
part of its own blob, so that every fruit keeps its whole outline (its size and
position). A piece left between the marked pixels smaller than MIN_CORE is no fruit of
its own (a speck the class's band did not quite cover) and is given back in the same
way; a blob with no piece that large (a small fruit squeezed between others) stays one
part, as without the class.
"""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np
import numpy.typing as npt
from scipy import ndimage

__all__ = ["BOUNDARY_THRESHOLD", "MIN_CORE", "fruit_parts"]

#: A fruit pixel is boundary where the network gives it more than this.
BOUNDARY_THRESHOLD = 0.5
#: Fewest pixels of a piece left between boundary pixels that is a fruit of its own (the
#: detector's least instance, ``instances.MIN_PIXELS``).
MIN_CORE = 6
_U8 = npt.NDArray[np.uint8]
_I32 = npt.NDArray[np.int32]
Parts = tuple[int, _I32, _I32]


def fruit_parts(binary: _U8, boundary: npt.NDArray[np.float32] | None) -> Parts:
    """The connected parts of the fruit mask ``binary`` (uint8, 0 or 1) as OpenCV's
    ``connectedComponentsWithStats`` gives them (count with the background, labels,
    stats), with the pixels where ``boundary`` (the network's boundary probability,
    the shape of ``binary``; None for a network without the class) is above
    BOUNDARY_THRESHOLD taken out first and given back to the nearest part of their
    own blob."""
    n, labels, stats, _ = cv2.connectedComponentsWithStats(binary, connectivity=8)
    if boundary is None or n <= 1:
        return n, cast(_I32, labels), cast(_I32, stats)
    removed = (binary > 0) & (boundary > BOUNDARY_THRESHOLD)
    if not removed.any():
        return n, cast(_I32, labels), cast(_I32, stats)
    core = cast(_U8, ((binary > 0) & ~removed).astype(np.uint8))
    m, cores, core_stats, _ = cv2.connectedComponentsWithStats(core, connectivity=8)
    specks = np.flatnonzero(core_stats[1:, 4] < MIN_CORE) + 1
    if specks.size:  # given back as boundary pixels are
        core[np.isin(cores, specks)] = 0
        removed = (binary > 0) & (core == 0)
        m, cores = cv2.connectedComponents(core, connectivity=8)
    # Blobs without any core pixel stay whole, with labels after the cores'.
    coreless = np.setdiff1d(np.unique(labels[removed]), np.unique(labels[core > 0]))
    parts = cores.astype(np.int32)
    for k, blob in enumerate(coreless.tolist(), start=m):
        parts[labels == blob] = k
    _give_back(parts, cast(_I32, labels), removed & (parts == 0))
    count = m + coreless.size
    return count, parts, _stats(parts, count)


def _give_back(parts: _I32, blobs: npt.NDArray[np.int32], pixels: npt.NDArray[np.bool_]) -> None:
    """Each of ``pixels`` (boundary pixels of blobs that have cores) to the nearest part
    (Euclidean) when that part lies in the same blob of ``blobs``; a pixel nearer
    another blob's part than its own (rare: across a gap) is left out."""
    _, (rows, cols) = ndimage.distance_transform_edt(parts == 0, return_indices=True)
    ys, xs = np.nonzero(pixels)
    ny, nx = rows[ys, xs], cols[ys, xs]
    same = blobs[ny, nx] == blobs[ys, xs]
    parts[ys[same], xs[same]] = parts[ny[same], nx[same]]


def _stats(parts: _I32, count: int) -> _I32:
    """OpenCV's component stats (x, y, width, height, area) of each label of ``parts``
    (row 0, the background, left zero)."""
    stats = np.zeros((count, 5), np.int32)
    for k, window in enumerate(ndimage.find_objects(parts, max_label=count - 1), start=1):
        if window is None:
            continue
        ys, xs = window
        area = int(np.count_nonzero(parts[window] == k))
        stats[k] = (xs.start, ys.start, xs.stop - xs.start, ys.stop - ys.start, area)
    return stats
