"""Edge-based sub-pixel refinement of marker corners.

``cornerSubPix`` (OpenCV's ``CORNER_REFINE_SUBPIX``) is built for saddle corners; on the
convex corner of a marker's black square it leaves a bias of about 0.1–0.2 px. Here each
side of the square is located instead: along the side, the intensity profile across it is
sampled (bilinear) and the edge is the centroid of the (signed) gradient, which for a
blurred, anti-aliased step is the step's position. The edge points are undistorted to
normalised coordinates, where the sides are straight lines (pinhole projection of a
straight edge), a line is fitted to each side (total least squares), and adjacent lines
intersect at the corners, which are then distorted back to pixels. Dozens of edge points
per side average the pixel noise down, which the four-point corner fit cannot do.

A clipped profile (a black level crushing the ink's foot, a white saturated in the sun)
biases the centroid towards one side by a few hundredths of a pixel, a tenth of a
millimetre or more in a marker body's pose. Where a marker's profiles read clipped
pixels, that bias is measured on the marker's own black border
(:mod:`softarm.vision.border_bias`) and the edges are moved back by it before the lines
are fitted again.

``EDGE_FIT`` (off) locates each profile's edge by a least-squares blurred-step fit
instead (:mod:`softarm.vision.edge_fit`), the border's inner edges too where the bias
is measured: under a camera's noise and JPEG its spread is under the centroid's, but on
sharp, clean edges (the bush's renders) it is biased by up to a few hundredths of a
pixel (docs/perception.md, "The edge by a blurred-step fit").
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np
import numpy.typing as npt

from softarm.vision._checks import FloatArray
from softarm.vision.border_bias import border_bias
from softarm.vision.camera_model import CameraModel
from softarm.vision.edge_fit import fit_edges

_STEP = 0.25  # px between profile samples across an edge
_MAX_REACH = 4.0  # px: the widest half-profile across an edge
_MAX_SHIFT = 2.0  # px: a refined corner further than this from the detection is refused
#: ... unless the sides' lines put it up to this share of the shortest side away and a
#: second pass from there agrees (refine_marker_corners: a corner the contour lost).
_MAX_JUMP = 0.25
#: The second pass drops edge points further than this many robust standard deviations
#: from their side's line before fitting it again.
_TRIM = 3.0
#: Profile levels (DN) that only clipped pixels give: at or under CLIP_LOW the camera
#: crushed the ink (its black level subtracted, then clipped at 0), at or over
#: CLIP_HIGH the paper saturated. A marker without them keeps the centroid's corners.
CLIP_LOW = 0.5
CLIP_HIGH = 254.5
#: The share of a marker's profile samples that must be clipped for the bias to be
#: measured (a crushed ink or a saturated paper clips 1-30 % of them on the row).
CLIPPED_SHARE = 0.002
#: Each profile's edge fitted by a blurred step (:mod:`softarm.vision.edge_fit`) instead
#: of the gradient's centroid; on a marker whose profiles read clipped pixels, the
#: border's inner edges too, so that the bias it measures is the fit's own. Off: on the
#: bush's clean renders the fit is biased (docs/perception.md, "The edge by a
#: blurred-step fit").
EDGE_FIT = False
#: Pixels beyond the corners' bounding box that one pass of the refinement reads (the
#: half-profile, one for the bilinear neighbour, one for rounding).
READ_MARGIN = int(_MAX_REACH) + 2


def read_margin(corners: FloatArray) -> int:
    """Pixels beyond the bounding box of a marker's detected ``corners`` (4, 2) that
    :func:`refine_marker_corners` may read, its second pass included: a copy of this
    neighbourhood is enough to refine the marker later."""
    quad = np.asarray(corners, dtype=np.float64).reshape(4, 2)
    return READ_MARGIN + int(np.ceil(_MAX_JUMP * _min_side(quad)))


def refine_marker_corners(
    gray: npt.NDArray[np.uint8],
    corners: FloatArray,
    camera: CameraModel,
    cells: int,
    origin: tuple[int, int] = (0, 0),
) -> FloatArray:
    """Refined (4, 2) pixel corners of one marker in the 2-D ``gray`` image (``cells`` =
    bits + 2 border cells); returns ``corners`` unchanged if the edges cannot be measured.

    ``gray`` may be a window of the frame whose top-left pixel is frame pixel ``origin``
    = (x0, y0); ``corners`` and the result are in frame pixels either way.

    A corner the detection's contour put far off (a dark berry or leaf over it joins the
    border) is found by the sides' lines, fitted on the profiles clear of it, a few pixels
    from the detection; the sides are then measured again from the corners found, and
    those are kept only where the second pass lands within ``_MAX_SHIFT`` of the first."""
    quad = np.asarray(corners, dtype=np.float64).reshape(4, 2)
    first = _refined(gray, quad, camera, cells, origin, _MAX_JUMP * _min_side(quad))
    if first is None:
        return quad
    if np.max(np.linalg.norm(first - quad, axis=1)) <= _MAX_SHIFT:
        return first
    again = _refined(gray, first, camera, cells, origin, _MAX_SHIFT, robust=True)
    return quad if again is None else again


def _min_side(quad: FloatArray) -> float:
    return float(np.min(np.linalg.norm(np.roll(quad, -1, axis=0) - quad, axis=1)))


def _refined(
    gray: npt.NDArray[np.uint8],
    quad: FloatArray,
    camera: CameraModel,
    cells: int,
    origin: tuple[int, int],
    max_shift: float,
    robust: bool = False,
) -> FloatArray | None:
    """One pass of :func:`refine_marker_corners` from the corners ``quad``: None when the
    edges cannot be measured or a corner lands further than ``max_shift`` px from ``quad``;
    ``robust``: the lines fitted again without the edge points far off them (what covers
    a corner also bends the profiles beside it)."""
    h, w = gray.shape
    ox, oy = int(origin[0]), int(origin[1])
    sides = np.roll(quad, -1, axis=0) - quad  # side k runs from corner k to corner k + 1
    lengths = np.sqrt(np.einsum("ij,ij->i", sides, sides))
    if lengths.min() < 8:
        return None
    # Half-width of the profile: well inside the black border cell, whatever the view;
    # a whole number of steps, so that the offsets are symmetric about 0.
    half = round(float(np.clip(0.4 * lengths.min() / cells, 1.0, _MAX_REACH)) / _STEP)
    reach = _STEP * half
    offsets: FloatArray = _STEP * np.arange(-half, half + 1, dtype=np.float64)
    normals = np.column_stack([sides[:, 1], -sides[:, 0]]) / lengths[:, None]
    # Profiles at evenly spaced points of each side, clear of the corners.
    counts = np.maximum(lengths.astype(int), 8)
    side = np.repeat(np.arange(4), counts)
    index = np.arange(side.size) - np.repeat(np.cumsum(counts) - counts, counts)
    margin = (np.maximum(3.0, 0.08 * lengths) / lengths)[side]
    fraction = margin + (1.0 - 2.0 * margin) * index / (counts[side] - 1)
    centre_px = quad[side] + fraction[:, None] * sides[side]  # (N, 2) points on the sides
    normal = normals[side]
    # Every sample lies within ``reach`` of the quad's sides.
    lo = np.floor(quad.min(axis=0) - reach - 1).astype(int)
    hi = np.ceil(quad.max(axis=0) + reach + 1).astype(int)
    if lo[0] < ox or lo[1] < oy or hi[0] > ox + w - 1 or hi[1] > oy + h - 1:
        return None
    # Work on a float copy of the marker's neighbourhood only (a full-frame copy costs ~1 ms).
    crop = gray[lo[1] - oy : hi[1] + 1 - oy, lo[0] - ox : hi[0] + 1 - ox].astype(np.float32)
    # Profile sample positions (N, m, 2) in the neighbourhood's pixels.
    across = offsets[None, :, None] * normal[:, None, :]
    pts = ((centre_px - lo)[:, None, :] + across).astype(np.float32)
    prof = cv2.remap(crop, pts, None, cv2.INTER_LINEAR)  # type: ignore[call-overload]  # (N, m); map2 None is valid, the stub wants an array
    # Signed gradient: for a box-filtered step sampled bilinearly its centroid is exactly the
    # step position (a squared or absolute gradient is biased by the sub-pixel phase or by
    # noise), and pixel noise adds zero-mean terms only.
    grad = np.diff(prof, axis=1)
    mid = 0.5 * (offsets[1:] + offsets[:-1])
    wsum = grad.sum(axis=1)
    contrast = np.abs(wsum)
    ok_edge = contrast > 0.25 * np.median(contrast)
    # Edge offset along the normal (in float64: a float32 @ float64 product would take
    # numpy's slow mixed-type loop instead of BLAS).
    shift = (grad.astype(np.float64) @ mid) / np.where(ok_edge, wsum, 1.0)
    good = ok_edge & (np.abs(shift) < reach)
    if np.any(np.bincount(side[good], minlength=4) < 4):
        return None
    clipped = np.count_nonzero((prof[good] <= CLIP_LOW) | (prof[good] >= CLIP_HIGH))
    unclipped = clipped < CLIPPED_SHARE * prof[good].size
    if EDGE_FIT:
        shift[good] = fit_edges(prof[good], offsets, shift[good])[0]
    edge = centre_px[good] + shift[good, None] * normal[good]
    side = side[good]
    fit = _fit_lines_trimmed if robust else _fit_lines
    centre, direction = fit(camera.normalize(edge), side)  # one call for all four
    pix = _corners(centre, direction, camera, quad, max_shift)
    if pix is None:
        return None
    if unclipped:
        return pix  # nothing clipped (a stray noisy pixel aside): the centroid is unbiased
    # Ink to quiet zone along each side's normal: the sign of its profiles' step.
    step = np.sign(np.bincount(side, np.sign(wsum[good]), 4))
    if np.any(step == 0):
        return pix
    outward = normals * step[:, None]
    locate = _fitted if EDGE_FIT else None  # the inner edges as the outer ones
    return _unbiased(
        crop, lo, pix, cells, offsets, outward, centre, direction, camera, max_shift, locate
    )


def _unbiased(
    crop: npt.NDArray[np.float32],
    crop_origin: npt.NDArray[np.int_],
    pix: FloatArray,
    cells: int,
    offsets: FloatArray,
    outward: FloatArray,
    centre: FloatArray,
    direction: FloatArray,
    camera: CameraModel,
    max_shift: float,
    locate: Callable[[FloatArray, FloatArray, FloatArray], FloatArray] | None = None,
) -> FloatArray:
    """The corners ``pix`` with the sides' lines (normalised: ``centre``, ``direction``)
    moved back by the bias the marker's border measures
    (:func:`~softarm.vision.border_bias.border_bias`); ``pix`` when it measures none or
    the moved corners fail. ``locate``: how the border's inner edges are located (as
    the outer ones were: :func:`_fitted`, or None for the centroid)."""
    bias = border_bias(crop, crop_origin, pix, cells, offsets, outward, locate)
    if bias == 0.0:
        return pix
    # Every edge point of a side moved alike moves its line, not its direction. A shift
    # of hundredths of a pixel, made in normalised coordinates through the focal lengths
    # (the lens's local stretch changes it by a few percent at most; undistorting the
    # points again would cost as much as the first fit).
    focal = np.array([camera.matrix[0, 0], camera.matrix[1, 1]])
    moved = _corners(centre - bias * outward / focal, direction, camera, pix, max_shift)
    return pix if moved is None else moved


def _corners(
    centre: FloatArray,
    direction: FloatArray,
    camera: CameraModel,
    quad: FloatArray,
    max_shift: float,
) -> FloatArray | None:
    """The (4, 2) pixel corners where the sides' lines (normalised, where the sides are
    straight: a point ``centre`` and a ``direction`` each) meet, corner k joining side
    k - 1 and side k; None when two adjacent lines are parallel or a corner lands further
    than ``max_shift`` px from ``quad``."""
    p1, d1 = np.roll(centre, 1, axis=0), np.roll(direction, 1, axis=0)  # side k - 1
    cross = d1[:, 0] * direction[:, 1] - d1[:, 1] * direction[:, 0]
    if np.min(np.abs(cross)) < 1e-9:
        return None
    gap = centre - p1
    s = (gap[:, 0] * direction[:, 1] - gap[:, 1] * direction[:, 0]) / cross
    lines = p1 + s[:, None] * d1
    pix = camera.project(np.column_stack([lines, np.ones(4)]))
    if np.max(np.linalg.norm(pix - quad, axis=1)) > max_shift:
        return None
    return pix


def _fit_lines(points: FloatArray, side: npt.NDArray[np.intp]) -> tuple[FloatArray, FloatArray]:
    """The total-least-squares line through the ``points`` of each side (``side`` =
    0..3): its centroid (4, 2) and unit direction (4, 2)."""
    n = np.bincount(side, minlength=4).astype(np.float64)
    centre = np.column_stack(
        [np.bincount(side, points[:, 0], 4) / n, np.bincount(side, points[:, 1], 4) / n]
    )
    d = points - centre[side]
    sxx = np.bincount(side, d[:, 0] * d[:, 0], 4)
    sxy = np.bincount(side, d[:, 0] * d[:, 1], 4)
    syy = np.bincount(side, d[:, 1] * d[:, 1], 4)
    # The line's direction is the principal axis of the scatter matrix [[sxx, sxy], [sxy, syy]].
    angle = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)
    direction = np.column_stack([np.cos(angle), np.sin(angle)])
    return centre, direction


def _fit_lines_trimmed(
    points: FloatArray, side: npt.NDArray[np.intp]
) -> tuple[FloatArray, FloatArray]:
    """:func:`_fit_lines` again on the points within _TRIM robust standard deviations
    (1.4826 MAD of the distances) of their side's first line; the first lines where a
    side would keep fewer than 4 points."""
    centre, direction = _fit_lines(points, side)
    normal = np.column_stack([-direction[:, 1], direction[:, 0]])
    distance = np.abs(np.einsum("ij,ij->i", points - centre[side], normal[side]))
    sigma = np.array([1.4826 * np.median(distance[side == k]) for k in range(4)])
    keep = distance <= _TRIM * sigma[side]
    if np.any(np.bincount(side[keep], minlength=4) < 4):
        return centre, direction
    return _fit_lines(points[keep], side[keep])


def _fitted(profiles: FloatArray, offsets: FloatArray, start: FloatArray) -> FloatArray:
    """The border's inner edges located as the outer ones are (:func:`fit_edges`)."""
    return fit_edges(profiles, offsets, start)[0]
