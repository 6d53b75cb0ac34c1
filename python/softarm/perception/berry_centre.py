"""A fruit's image centre to a fraction of a pixel: the centroid of its silhouette with
each edge pixel counted by how much of it is fruit.

A thresholded mask counts an edge pixel wholly in or wholly out, and which way it goes
depends on the background behind it: a fruit's edge against a bright leaf blurs above
the dark threshold and drops out of the mask, against a dark ground it stays in. The
mask's centroid so moves towards the darker background, by 0.2-0.3 px on C1's berries
at 1 m (a third of a millimetre across C1's ray, half a millimetre along the approach
once C2's ray crosses it: docs/harvest.md, "Where the fine error comes from").

An edge pixel's brightness is the mix of the fruit's and the background's in the
share of the pixel each covers (the optics' blur, then the detector's 3x3 blur, spread
an edge over about one pixel either side), so the fruit's share of it is
(background - pixel) / (background - fruit). The fruit's brightness is the median of
the mask's interior; the background's is taken in each of :data:`SECTORS` directions
around the fruit from a ring just outside the blurred edge, since a fruit hangs in
front of leaves on one side and sky or ground on another. The fruit's brightness too
is taken in each direction, from its own pixels just inside the edge: a fruit is shaded,
its side towards the light brighter (and its drupelets' highlights there), the other
side darker, and one colour for the whole fruit read the lit edge's pixels as part
background and the dark edge's as all fruit: the centre leaned away from the light, by
0.2 px on C1's berries (52 of 58 on bushes 1500-1509; docs/harvest.md, "The lean of
C1's centre"). Where fruit and background are of about the same brightness the edge
carries no such information, and the mask's own pixels count.
"""

from __future__ import annotations

from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

_U8 = npt.NDArray[np.uint8]

__all__ = ["EDGE", "SECTORS", "SHADE", "silhouette_centre"]

#: The blurred edge: this many pixels either side of the mask's boundary.
EDGE = 1
#: The background ring, this many pixels (from, to) outside the mask: past the edge.
RING = (4, 7)
#: The fruit's own colour near its edge: the interior pixels this many deep inside the
#: edge (1: the layer next to it, where the shading is the edge's).
SHADE = 1
#: Directions around the fruit whose backgrounds are taken apart.
SECTORS = 8
#: Below this colour difference (BGR, 0-255) fruit and background are not told apart.
MIN_CONTRAST = 4.0
#: Fewest pixels of interior and of ring for a refined centre.
MIN_PIXELS = 5


def _disk(radius: int) -> npt.NDArray[np.uint8]:
    return cast(_U8, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1)))


def silhouette_centre(
    mask: npt.NDArray[np.bool_],
    colour: npt.NDArray[np.uint8],
    origin: tuple[int, int],
    centre: tuple[float, float],
) -> tuple[float, float]:
    """The fruit's centre (x, y) px in the image: the coverage-weighted centroid of
    its silhouette (see the module docstring).

    ``mask`` is the fruit's pixels over a window of the image whose pixel (0, 0) is
    the image's ``origin`` (x, y); ``colour`` the image (H, W, 3) over the same window,
    which must reach :data:`RING` pixels beyond the mask where the image does;
    ``centre`` the mask's own centroid, returned as it is when the window holds too
    few interior or background pixels to refine it.
    """
    m = mask.astype(np.uint8)
    inner = cv2.erode(m, _disk(EDGE)) > 0
    edge = (cv2.dilate(m, _disk(EDGE + 1)) > 0) & ~inner
    ring = (cv2.dilate(m, _disk(RING[1])) > 0) & ~(cv2.dilate(m, _disk(RING[0])) > 0)
    iy, ix = np.nonzero(inner)
    ry, rx = np.nonzero(ring)
    if iy.size < MIN_PIXELS or ry.size < MIN_PIXELS:
        return centre
    ox, oy = origin
    cx, cy = centre[0] - ox, centre[1] - oy
    ey, ex = np.nonzero(edge)
    sector = _sector(ex - cx, ey - cy)
    background = _medians(colour[ry, rx], _sector(rx - cx, ry - cy))[sector]
    # The fruit's colour beside each edge pixel: its shading there (module docstring).
    near = inner & ~(cv2.erode(m, _disk(EDGE + SHADE)) > 0)
    ny, nx = np.nonzero(near)
    if ny.size < MIN_PIXELS:
        ny, nx = iy, ix
    fruit = _medians(colour[ny, nx], _sector(nx - cx, ny - cy))[sector]
    # A pixel's colour is the mix p = s f + (1 - s) b of fruit f and background b in
    # its share s of fruit: s is the projection of b - p on b - f.
    line = background - fruit
    contrast = np.einsum("ij,ij->i", line, line)
    told = contrast >= MIN_CONTRAST**2
    along = np.einsum("ij,ij->i", background - colour[ey, ex], line)
    share = np.clip(along / np.where(told, contrast, 1.0), 0.0, 1.0)
    share = np.where(told, share, mask[ey, ex])
    total = iy.size + float(share.sum())
    x = (float(ix.sum()) + float(share @ ex)) / total
    y = (float(iy.sum()) + float(share @ ey)) / total
    return x + ox, y + oy


def _sector(dx: npt.NDArray[np.floating], dy: npt.NDArray[np.floating]) -> npt.NDArray[np.intp]:
    """Which of :data:`SECTORS` directions each offset (dx, dy) points in."""
    turn = (np.arctan2(dy, dx) + np.pi) / (2 * np.pi)
    return np.asarray(np.floor(turn * SECTORS).astype(np.intp) % SECTORS)


def _medians(
    colour: npt.NDArray[np.uint8], sector: npt.NDArray[np.intp]
) -> npt.NDArray[np.float64]:
    """Each sector's colour (SECTORS, 3): the median of the pixels ``colour`` (n, 3) in
    it, or of all of them where it holds too few."""
    out = np.empty((SECTORS, colour.shape[1]))
    out[:] = np.median(colour, axis=0)
    counts = np.bincount(sector, minlength=SECTORS)
    for k in np.flatnonzero(counts >= MIN_PIXELS):
        out[k] = np.median(colour[sector == k], axis=0)
    return out
