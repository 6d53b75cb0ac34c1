"""The training target of ``softarm detector train --distance`` (:mod:`..distance` reads the
network's output): each fruit pixel's distance to the edge of its own fruit (its visible
mask: another fruit, a leaf or the background all end it), divided by that fruit's
largest, so that every fruit's hill rises from near 0 at its edge to 1 at its centre
whatever its size (Bai and Urtasun's "deep watershed", normalised per instance). Two
touching fruit meet in a valley near 0 however small either is; a band of fixed width
(:mod:`..boundary`) covered small fruit whole."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

__all__ = ["distance_target"]

_F32 = npt.NDArray[np.float32]


def distance_target(owner: npt.NDArray[np.int32]) -> _F32:
    """The normalised distance of an instance map ``owner`` (0 off fruit, k > 0 on fruit
    k): on fruit k, (d − ½) / (max d − ½), d a pixel's Euclidean distance (px) to the
    nearest pixel not of fruit k (½ for a pixel on its edge: the distance from the pixel's
    centre to the edge line, so that an edge pixel is near 0 on a large fruit and a lone
    pixel is 1); 0 off fruit."""
    out = np.zeros(owner.shape, np.float32)
    h, w = owner.shape
    for k in np.unique(owner[owner > 0]).tolist():
        rows, cols = np.nonzero(owner == k)
        # A window one pixel wider than the fruit, so that its edge is inside it (a fruit
        # cut by the image's border ends there too).
        y0, y1 = max(0, rows.min() - 1), min(h, rows.max() + 2)
        x0, x1 = max(0, cols.min() - 1), min(w, cols.max() + 2)
        mine = np.zeros((y1 - y0 + 2, x1 - x0 + 2), np.uint8)
        mine[1:-1, 1:-1] = owner[y0:y1, x0:x1] == k
        d = cv2.distanceTransform(mine, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
        top = float(d.max())
        inside = mine[1:-1, 1:-1] > 0
        values = (d - 0.5) / (top - 0.5) if top > 0.5 else np.ones_like(d)
        out[y0:y1, x0:x1][inside] = np.clip(values[inside], 0.0, 1.0)
    return out
