"""Depth as a check on a berry detection: where a depth image is given, a detection is
kept only when its depth says "a fruit": its metric radius (pixel radius, depth and
focal length) is a berry's, its depth lies in the working range, and its pixels lie on
one fruit-sized surface rather than straddling a depth edge (a shadow across a leaf and
the ground behind it, two things side by side).

A sphere's depth relief is checked against the best plane through the blob's depths,
so that a tilted flat surface (the hedge's face, a leaf) is not taken for the fruit's
own relief. The fruit's size is softarm's blackberry model, the renderer's (``BERRY_HALF`` cores of
9.5 × 9.5 × 12 mm half-size with drupelets to 1.18–1.19 times the half-width beyond
them, scaled 0.8–1.15: ``softarm.sim.render.mjcf`` and ``row_mjcf``), copied here
because perception may not import the simulation; a test keeps the two equal. None of
the check's numbers was tuned on the evaluation renders (docs/perception.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from softarm.errors import InputError

__all__ = [
    "FRUIT_RADIUS_M",
    "MIN_VISIBLE_SHARE",
    "SPHERE_RELIEF",
    "DepthCheck",
    "Rejection",
    "metric_radius",
    "rejection",
]

#: A fruit's outline radius (m): the smallest fruit's half-width (8.97 mm: 0.8 × 1.18 ×
#: 9.5 mm) to the largest one's half-length (15.44 mm: 1.15 × (0.85 × 12 + 0.34 × 9.5)
#: mm), drupelets included.
FRUIT_RADIUS_M = (0.00897, 0.01544)
#: The least visible share of a fruit a detection stands for: the evaluation counts the
#: fruit at least half visible, whose equivalent radius is then sqrt(1/2) of the whole's.
MIN_VISIBLE_SHARE = 0.5
#: A whole sphere cap's depth relief seen face on: the RMS of its depth about the mean,
#: as a share of its radius (sqrt(1/18): depth R(1 - sqrt(1 - u)), u uniform in [0, 1]).
SPHERE_RELIEF = float(np.sqrt(1.0 / 18.0))
#: Why a detection was dropped.
Rejection = Literal["size", "range", "sphere"]


@dataclass(frozen=True)
class DepthCheck:
    """What depth must say of a detection.

    ``fruit_radius_m``: the fruit's outline radius (m); ``outline_px``: how far a mask's
    outline may lie from the fruit's (the 5 × 5 closing, the network's 2× upsampling),
    allowed on either bound of the radius and on the sphere's depth; ``range_m``: the
    depths (m) a fruit may be at (C2 at its closest, about 6 cm from a fruit's centre in
    the training renders, halved; the row's far fruit at 2.7 m, with a margin);
    ``sphere_share``: the least share of the detection's pixels of known depth within
    the fruit's radius of their median (a sphere's visible cap lies within it; a blob
    across a depth edge does not, most of it); ``min_relief``: the least depth relief
    of those pixels off their best plane, as a share of a whole sphere cap's (RMS
    sqrt(1/18) of its radius): a flat thing (a leaf, the hedge's face, a berry's
    picture) has none. 0 turns it off, for a depth too smooth to show a fruit's relief
    (a stereo depth filtered over windows wider than the fruit).
    """

    fruit_radius_m: tuple[float, float] = FRUIT_RADIUS_M
    outline_px: float = 2.0
    range_m: tuple[float, float] = (0.03, 3.0)
    sphere_share: float = 0.5
    min_relief: float = 0.5

    def __post_init__(self) -> None:
        for name in ("fruit_radius_m", "range_m"):
            lo, hi = getattr(self, name)
            if not (np.isfinite(lo) and np.isfinite(hi) and 0 <= lo < hi):
                raise InputError(f"DepthCheck.{name} must be (low, high) with 0 <= low < high")
        if not (np.isfinite(self.outline_px) and self.outline_px >= 0):
            raise InputError("DepthCheck.outline_px must be a finite number >= 0")
        for name in ("sphere_share", "min_relief"):
            if not 0 <= getattr(self, name) <= 1:
                raise InputError(f"DepthCheck.{name} must be in [0, 1]")


def metric_radius(radius_px: float, surface_m: float, focal_px: float) -> float:
    """The radius (m) of a sphere whose outline is ``radius_px`` across the image and
    whose near surface is ``surface_m`` away: the outline's half-angle θ (tan θ = r / f)
    gives R = s sin θ / (1 − sin θ), exact for a sphere on the optical axis; at C2's
    6 cm the plain r s / f is 17 % short."""
    sin = float(np.sin(np.arctan2(radius_px, focal_px)))
    return surface_m * sin / max(1.0 - sin, 1e-9)


def rejection(
    mask: npt.NDArray[np.bool_],
    radius_px: float,
    depth: npt.NDArray[np.floating],
    focal_px: float,
    check: DepthCheck,
) -> Rejection | None:
    """Why depth rejects a detection (None: it does not, or its depth is unknown).

    ``mask`` the detection's pixels over its box, ``depth`` (m; NaN, 0 or ±inf unknown)
    the same box, ``radius_px`` its equivalent radius."""
    z = depth[mask]
    known = np.isfinite(z) & (z > 0)
    if not known.any():
        return None
    z = z[known]
    surface = float(np.median(z))
    lo, hi = check.range_m
    if not lo <= surface <= hi:
        return "range"
    slack = check.outline_px * surface / focal_px
    radius = metric_radius(radius_px, surface, focal_px)
    r_min, r_max = check.fruit_radius_m
    if not r_min * np.sqrt(MIN_VISIBLE_SHARE) - slack <= radius <= r_max + slack:
        return "size"
    rows, cols = np.nonzero(mask)
    near = np.abs(z - surface) <= radius + slack
    if np.count_nonzero(near) < max(check.sphere_share * z.size, 3):
        return "sphere"
    relief = _relief(rows[known][near], cols[known][near], z[near])
    if relief < check.min_relief * SPHERE_RELIEF * radius:
        return "sphere"
    return None


def _relief(
    rows: npt.NDArray[np.intp], cols: npt.NDArray[np.intp], z: npt.NDArray[np.floating]
) -> float:
    """The RMS (m) of the depths ``z`` at pixels (``rows``, ``cols``) off their
    least-squares plane: what a tilted flat surface lacks and a sphere's cap has."""
    a = np.column_stack([np.ones(z.size), rows - rows.mean(), cols - cols.mean()])
    coef, *_ = np.linalg.lstsq(a, z.astype(np.float64), rcond=None)
    return float(np.sqrt(np.mean((z - a @ coef) ** 2)))
