"""Merged fruit split by the size depth expects (``DetectorSettings.split_by_size``).

Where a depth image is given, a blob's median depth s says how large one fruit looks:
a sphere of radius R whose near surface is s away has an outline of half-angle θ with
sin θ = R / (s + R), so of r = f tan θ pixels (the inverse of
:func:`~.depth_check.metric_radius`). The depth check drops a blob whose equivalent
radius is over the largest fruit's (``fruit_radius_m[1]``, the largest fruit's
half-length, plus the outline's allowance): such a blob is two fruit or more, merged
(fruit that touch, drawn as one part by the network or one blob by the colour rule).
Here it is cut into k pieces first, each then placed and checked as any detection.

How many: occlusion only hides area, so a blob of area A holds at least
ceil(A / a_max) fruit, a_max the area of the check's largest fruit (a disc of its
radius bound); it could hold more (smaller fruit, or fruit seen end on), which area
alone cannot tell from fewer large ones. The blob's shape is asked next: the peaks of
its distance map that the neck test of :mod:`.touching` keeps are fruit it shows
apart; k is their number, clipped to [ceil(A / a_max), floor(A / a_min)] (a_min the
smallest fruit half visible, the least the check keeps) and to :data:`MAX_FRUIT`. An
elongated fruit (a blackberry seen from its side is 1.2 times longer than wide) is
never split: its area is below a_max by construction of the bound (its half-length is
the bound's radius), and a lone fruit whatever its shape passes the size test whole.

Where: Lloyd's k-means on the blob's pixel coordinates (pieces of about equal area,
which k fruit of one size at one depth are), seeded by the k seeds above, then by the
pixel farthest from the seeds so far, deepest in the blob first (deterministic: no
random start). Each pixel goes to its nearest centre; the cut between two equal
touching discs falls at their contact and each centre at its disc's."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt
from scipy.cluster.vq import kmeans2

from softarm.perception.detector.depth_check import MIN_VISIBLE_SHARE, DepthCheck
from softarm.perception.detector.touching import Seed, _distance, disc_seeds

__all__ = ["MAX_FRUIT", "SEED_SHARE", "SizeSplit", "apparent_radius", "lloyd_pieces"]

#: The most fruit one blob is cut into: a cluster of touching fruit holds a few; a
#: larger fruit-coloured patch (a shadow, a dark leaf) is left whole for the check to
#: drop rather than tiled into fruit-sized pieces.
MAX_FRUIT = 4
#: A fruit the shape shows apart is a distance-map peak at least this share of the
#: smallest fruit's radius deep (a half-visible disc's inscribed radius is half its own).
SEED_SHARE = 0.5
#: Lloyd iterations (converged ones change nothing).
ITERATIONS = 20
_F32 = npt.NDArray[np.float32]
_Mask = npt.NDArray[np.bool_]
_Contour = npt.NDArray[np.int32]


def apparent_radius(radius_m: float, surface_m: float, focal_px: float) -> float:
    """The outline radius (px) of a sphere of ``radius_m`` whose near surface is
    ``surface_m`` away: f tan θ with sin θ = R / (s + R), the inverse of
    :func:`~.depth_check.metric_radius`."""
    sin = radius_m / max(surface_m + radius_m, 1e-9)
    return focal_px * sin / float(np.sqrt(max(1.0 - sin * sin, 1e-12)))


@dataclass(frozen=True)
class SizeSplit:
    """Cuts blobs of more than one fruit's area: ``depth`` (m; NaN, 0 or ±inf unknown)
    on the grid the blobs are drawn on, ``focal_px`` on that grid, ``outline_px`` the
    outline's allowance on that grid, ``check`` the fruit's size bounds."""

    depth: npt.NDArray[np.floating]
    focal_px: float
    check: DepthCheck
    outline_px: float

    def plan(self, mask: _Mask, x: int, y: int) -> tuple[int, list[Seed]]:
        """How many fruit the blob ``mask`` (its window at (x, y) of the grid) holds (1
        when its depth is unknown or its area one fruit's), and the fruit its shape
        shows apart (:func:`~.touching.disc_seeds`, at least half the smallest fruit's
        radius deep: a half-visible fruit's inscribed disc)."""
        h, w = mask.shape
        z = self.depth[y : y + h, x : x + w][mask]
        z = z[np.isfinite(z) & (z > 0)]
        if z.size == 0:
            return 1, []
        surface = float(np.median(z))
        r_min, r_max = self.check.fruit_radius_m
        hi = apparent_radius(r_max, surface, self.focal_px) + self.outline_px
        area = float(np.count_nonzero(mask))
        fewest = int(np.ceil(area / (np.pi * hi**2)))
        if fewest < 2 or fewest > MAX_FRUIT:
            # One fruit's area; or no cluster of fruit, left whole for the check to drop.
            return 1, []
        lo = max(apparent_radius(r_min, surface, self.focal_px) - self.outline_px, 1.0)
        most = int(area / (np.pi * MIN_VISIBLE_SHARE * lo**2))
        shown = disc_seeds(mask, SEED_SHARE * lo)
        return int(np.clip(len(shown), fewest, max(min(most, MAX_FRUIT), fewest))), shown

    def pieces(self, mask: _Mask, x: int, y: int) -> list[_Mask]:
        """``mask`` (its window at (x, y) of the grid) as one mask per fruit it holds."""
        k, shown = self.plan(mask, x, y)
        return [mask] if k < 2 else lloyd_pieces(mask, k, shown)

    def least_split_area(self) -> float:
        """The least area (px) a blob must have to be cut at all: the largest fruit's
        at the farthest depth the check allows (the smallest that fruit looks), so that
        the specks of a frame cost no depth look-up."""
        far = self.check.range_m[1]
        return float(
            np.pi
            * (apparent_radius(self.check.fruit_radius_m[1], far, self.focal_px) + self.outline_px)
            ** 2
        )

    def contours(self, contour: _Contour) -> list[_Contour]:
        """A blob's outer ``contour`` (image px) as one outline per fruit it holds."""
        # Its pixels number at most its polygon's area plus its outline's length (Pick).
        if cv2.contourArea(contour) + len(contour) <= self.least_split_area():
            return [contour]
        bx, by, bw, bh = cv2.boundingRect(contour)
        filled = np.zeros((bh, bw), np.uint8)
        cv2.drawContours(filled, [contour], -1, 1, thickness=cv2.FILLED, offset=(-bx, -by))
        parts = self.pieces(filled > 0, bx, by)
        if len(parts) < 2:
            return [contour]
        out: list[_Contour] = []
        for part in parts:
            found, _ = cv2.findContours(
                part.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE, offset=(bx, by)
            )
            out.extend(cast(list[_Contour], list(found)))
        return out


def _seeds(mask: _Mask, k: int, shown: list[Seed]) -> npt.NDArray[np.float64]:
    """k starting centres (row, col): the fruit the shape shows apart (``shown``,
    highest first), then the pixel farthest from the centres so far, ties to the one
    deepest in the blob."""
    dist = _distance(mask)
    rows, cols = np.nonzero(mask)
    depth_in = dist[rows, cols].astype(np.float64)
    seeds = [(r, c) for r, c, _ in shown][:k]
    if not seeds:
        top = int(np.argmax(depth_in))
        seeds = [(float(rows[top]), float(cols[top]))]
    while len(seeds) < k:
        far = np.min([np.hypot(rows - r, cols - c) for r, c in seeds], axis=0)
        best = int(np.lexsort((-depth_in, -far))[0])
        seeds.append((float(rows[best]), float(cols[best])))
    return np.array(seeds, np.float64)


def lloyd_pieces(mask: _Mask, k: int, shown: list[Seed] | None = None) -> list[_Mask]:
    """``mask`` cut into ``k`` pieces by Lloyd's k-means on its pixel coordinates
    (``scipy.cluster.vq.kmeans2``), started at the fruit ``shown`` apart by its shape
    and then as :func:`_seeds` says."""
    rows, cols = np.nonzero(mask)
    points = np.column_stack([rows, cols]).astype(np.float64)
    with warnings.catch_warnings():
        # A centre left with no pixel keeps its place (its piece is then empty, dropped).
        warnings.simplefilter("ignore", UserWarning)
        _, owner = kmeans2(points, _seeds(mask, k, shown or []), ITERATIONS, minit="matrix")
    out = []
    for j in range(k):
        piece = np.zeros_like(mask)
        piece[rows[owner == j], cols[owner == j]] = True
        if piece.any():
            out.append(piece)
    return out
