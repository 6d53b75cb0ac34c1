"""Canes from C1: segmented in colour, lifted to 3D by stereo (or an aligned depth
image), split into canes and each fitted as a ``softarm.PolynomialCurve``, the planning
paper's curve obstacle (eq. 10), in the base frame, with its radius.

The pipeline (:func:`fit_canes`):

1. rectify the pair; the cane pixels of the rectified left image, from the chosen
   source (:mod:`softarm.perception.cane_source`: the colour-and-width mask of
   :func:`softarm.perception.cane_pixels.cane_mask` by default, or the network's);
2. their disparity by StereoSGBM over the region they occupy, triangulated to the left
   camera frame (with ``depth`` given: the left image's own pixels, back-projected);
3. the camera sees the front of each tube, on average π r / 4 nearer than its centre
   line for pixels spread evenly across it: each point is pushed back along its ray by
   that much, r from the local width of the mask;
4. the points beyond ``CaneSettings.reach`` of the base dropped, and only then the rest
   evenly subsampled to the fit's budget (``max_points``): in a row most cane pixels are
   the next row's and the hedge's, and a budget spread over the whole image left the
   canes in reach a few points each;
5. in the base frame, sequential RANSAC splits the points into canes
   (:mod:`softarm.perception.cane_curves`) and each becomes a cubic in u ∈ [0, 1]
   fitted by least squares with arc-length parameters;
6. with ``CaneSettings.evidence`` set, only the curves that show a cane's evidence
   (:mod:`softarm.perception.cane_evidence`: points per metre, radius) are kept.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm._core import PolynomialCurve
from softarm.checks import FloatArray, as_array, finite_real
from softarm.errors import ParameterError, VisionError
from softarm.perception._inputs import bgr_image, depth_metres, instance, instance_or_default
from softarm.perception.cane_curves import CurveSearch, arc_length_cubic, split_into_curves
from softarm.perception.cane_evidence import CaneEvidence, shows_a_cane
from softarm.perception.cane_pixels import CaneLook, half_width_px, matched_disparity
from softarm.perception.cane_source import check_cane_source, source_mask
from softarm.perception.self_filter import CANE_REACH
from softarm.vision.stereo_camera import StereoCamera

__all__ = [
    "CaneFit",
    "CaneSettings",
    "cane_points",
    "centre_line_points",
    "even_subsample",
    "fit_cane_points",
    "fit_canes",
    "mask_points",
]


@dataclass(frozen=True)
class CaneFit:
    """One cane: ``curve`` (planning paper eq. 10, u ∈ [0, 1], base frame) with its
    ``coeffs`` (3, 4), ascending powers; ``radius`` (m); ``points`` (n, 3) the 3D
    inliers it was fitted to (centre-line estimates, base frame); ``support`` = n."""

    curve: PolynomialCurve
    coeffs: FloatArray
    radius: float
    points: FloatArray
    support: int


@dataclass(frozen=True)
class CaneSettings:
    """``look``: which pixels are canes; ``search``: how points become canes;
    ``depth_range``: nearest and farthest depth (m) a cane is looked for at;
    ``match_far``: the farthest depth (m) C1's stereo matches at, beyond
    ``depth_range``'s far end (None: that end): a cane farther than the range (the next
    row's, the hedge's) is then matched at its own depth and dropped, where a search
    that stops at the range can only match it to a wrong, nearer disparity, a phantom
    (3 m with 8,000 points, an 8 cm support and the evidence of 70 points and 1.75 mm:
    on fresh seeds 310180–310199 more coverage in every look of the row, but less
    precision in dusk and backlight: not the default, docs/perception.md);
    ``ties_in_range``: with ``match_far`` set, a pixel the search out to ``match_far``
    leaves unmatched because a match beyond the range ties with one within it (SGBM's
    uniqueness ratio) takes the match within the range
    (:func:`softarm.perception.cane_pixels.matched_disparity`; False: it stays
    unmatched, as the far match was first measured; with the far budget, on fresh seeds
    312000–312019 it covered 0.04–0.09 more of the row than without and was 0.02–0.05
    less precise, in backlight 0.023 below today's default: not the default either,
    docs/perception.md);
    ``reach``: points farther than this (m) from the base origin are dropped before the
    budget is spent (the map's own reach, :data:`softarm.perception.self_filter.
    CANE_REACH`: canes beyond it cannot touch the arm; None: every point shares the
    budget, as before the reach was used); ``max_points``: points kept for the fit, an
    even subsample of those within ``reach`` beyond that (4,000; 8,000 with a support
    length of 8 cm instead of 70 points covered 0.10–0.19 more of the row's canes on
    fresh seeds 310140–310159 but lost 0.05–0.17 of precision: not adopted, the figures
    in docs/perception.md);
    ``smoothness``: StereoSGBM's penalties P1, P2 (see
    :func:`softarm.perception.cane_pixels.stereo_disparity`); ``source``: where the cane
    pixels come from (:data:`softarm.perception.cane_source.CANE_SOURCES`; None: this
    process's choice, :func:`~softarm.perception.cane_source.use_cane_source`);
    ``evidence``: what a fitted curve must show to be kept
    (:class:`~softarm.perception.cane_evidence.CaneEvidence`; None: every curve the
    search finds is kept; with 8,000 points and an 8 cm support it lifted the row's
    coverage on fresh seeds 310160–310179 but left the overcast map 0.028 less precise:
    not the default, docs/perception.md).

    Raises:
        ParameterError: ``source`` is not None or one of CANE_SOURCES; ``reach`` is not
            None or a finite number > 0; ``evidence`` is not None or a CaneEvidence;
            ``match_far`` is not None or a finite number beyond ``depth_range``'s far
            end; ``ties_in_range`` is not a bool.
    """

    look: CaneLook = field(default_factory=CaneLook)
    search: CurveSearch = field(default_factory=CurveSearch)
    depth_range: tuple[float, float] = (0.6, 1.5)
    max_points: int = 4000
    smoothness: tuple[int, int] = (4, 16)
    source: str | None = None
    reach: float | None = CANE_REACH
    evidence: CaneEvidence | None = None
    match_far: float | None = None
    ties_in_range: bool = True

    def __post_init__(self) -> None:
        if self.evidence is not None and not isinstance(self.evidence, CaneEvidence):
            raise ParameterError(
                f"settings.evidence must be None or a CaneEvidence, got {self.evidence!r}"
            )
        if not isinstance(self.ties_in_range, bool):
            raise ParameterError(
                f"settings.ties_in_range must be a bool, got {self.ties_in_range!r}"
            )
        if self.source is not None:
            check_cane_source(self.source, "settings.source")
        if self.match_far is not None and not (
            finite_real(self.match_far) and self.match_far >= self.depth_range[1]
        ):
            raise ParameterError(
                f"settings.match_far must be None or a number >= depth_range's far end "
                f"{self.depth_range[1]} m, got {self.match_far!r}"
            )
        if self.reach is not None and not (finite_real(self.reach) and self.reach > 0):
            raise ParameterError(
                f"settings.reach must be None or a number > 0 m, got {self.reach!r}"
            )


def fit_canes(
    left: npt.NDArray[np.uint8],
    right: npt.NDArray[np.uint8] | None,
    stereo: StereoCamera,
    depth: npt.NDArray[np.floating[Any]] | None = None,
    settings: CaneSettings | None = None,
) -> list[CaneFit]:
    """The canes C1 sees, largest support first; [] when there is none.

    Args:
        left, right: C1's BGR uint8 images as OpenCV reads them (distorted, the size of
            ``stereo.left.image_size``). ``right`` may be None when ``depth`` is given.
        stereo: the calibrated pair; ``stereo.T_base_left`` places the result.
        depth: optional (H, W) float depth in metres along the left eye's optical
            axis, aligned with ``left`` (0 or NaN where unknown), e.g. from an RGB-D
            camera; when given, stereo matching is skipped. A uint16 depth in
            millimetres is refused, as by :func:`~softarm.perception.berries.
            detect_berries`: divide it by 1000 first.
        settings: thresholds; the defaults were tuned on rendered bushes 0–4 and
            900–919.

    Raises:
        VisionError: an empty image, a wrong dtype or shape, a frame that is not the
            calibrated size, or a depth that is not float metres of that size.
        InputError: ``stereo`` is not a StereoCamera, or ``settings`` not a
            CaneSettings.
    """
    settings = instance_or_default(settings, CaneSettings, "settings")
    return fit_cane_points(cane_points(left, right, stereo, depth, settings), settings)


def cane_points(
    left: npt.NDArray[np.uint8],
    right: npt.NDArray[np.uint8] | None,
    stereo: StereoCamera,
    depth: npt.NDArray[np.floating[Any]] | None = None,
    settings: CaneSettings | None = None,
) -> FloatArray:
    """(n, 4) rows, at most ``settings.max_points``: a point on a cane's centre line C1
    sees (base frame, m) within ``settings.reach`` of the base and the cane's radius
    there (m); arguments and errors as :func:`fit_canes`."""
    settings = instance_or_default(settings, CaneSettings, "settings")
    _check_inputs(left, right, stereo, depth)
    if depth is None:
        assert right is not None
        rect_left, rect_right = stereo.rectification.rectify(left, right)
        mask = source_mask(rect_left, settings.look, settings.source)
        return mask_points(rect_left, rect_right, stereo, mask, settings)
    return _depth_points(left, depth, stereo, settings)


def _to_base(camera_points: FloatArray, stereo: StereoCamera) -> FloatArray:
    """(n, 4) rows in the left camera frame placed in the base frame."""
    T = np.asarray(stereo.T_base_left, dtype=np.float64)
    return np.column_stack([camera_points[:, :3] @ T[:3, :3].T + T[:3, 3], camera_points[:, 3]])


def fit_cane_points(points: FloatArray, settings: CaneSettings | None = None) -> list[CaneFit]:
    """The canes among ``points`` (n, 4), as :func:`cane_points` gives them (and
    :func:`softarm.perception.cane_views.view_pair_points` for other views), largest
    support first; [] when there are too few.

    Raises:
        InputError: ``points`` is not a finite (n, 4) array (ShapeError,
            NonFiniteError), or a radius (its last column) is not > 0
            (ParameterError); ``settings`` is not a CaneSettings.
    """
    settings = instance_or_default(settings, CaneSettings, "settings")
    points = as_array(points, (None, 4), "points")
    if np.any(points[:, 3] <= 0.0):
        raise ParameterError("points[:, 3], the canes' radii, must all be > 0 m")
    if len(points) < settings.search.min_support:
        return []
    return _fit_all(points[:, :3], points[:, 3], settings)


def _check_inputs(left: object, right: object, stereo: StereoCamera, depth: object) -> None:
    """The checks of :func:`softarm.perception._inputs`, shared with the berries."""
    instance(stereo, StereoCamera, "stereo")
    checked = bgr_image(left, "left", stereo.left.image_size)
    if depth is None:
        if right is None:
            raise VisionError("right is None: give the right image or a depth image")
        bgr_image(right, "right", stereo.right.image_size)
        return
    depth_metres(depth, checked.shape)


def mask_points(
    rect_left: npt.NDArray[np.uint8], rect_right: npt.NDArray[np.uint8], stereo: StereoCamera,
    mask: npt.NDArray[np.bool_], settings: CaneSettings,
) -> FloatArray:  # fmt: skip
    """(n, 4) rows as :func:`cane_points` gives them (base frame), one per pixel of the
    cane pixels ``mask`` (a source's, of ``rect_left``) with a disparity, from the
    already rectified pair ``rect_left``, ``rect_right`` of ``stereo``: what follows the
    choice of source, the same for every source (and for the comparison of sources,
    :mod:`softarm.experiments.cane_sources`)."""
    rect = stereo.rectification
    disparity = matched_disparity(
        rect_left, rect_right, rect, mask, settings.depth_range, settings.match_far,
        settings.smoothness, settings.ties_in_range,
    )  # fmt: skip
    mask = mask & np.isfinite(disparity)
    rows, cols = _whole_view_budget(np.nonzero(mask), settings)
    pixels = np.column_stack([cols, rows]).astype(np.float64)
    surface = rect.triangulate(pixels, disparity[rows, cols])
    radius = half_width_px(mask)[rows, cols] * surface[:, 2] / rect.focal
    centre = _to_base(_to_centre_line(surface, radius, settings.depth_range), stereo)
    return _within_budget(centre, settings.reach, settings.max_points)


def _depth_points(
    left: npt.NDArray[np.uint8], depth: npt.NDArray[np.floating[Any]],
    stereo: StereoCamera, settings: CaneSettings,
) -> FloatArray:  # fmt: skip
    """(n, 4) rows as :func:`mask_points` gives them, from a depth image aligned with the
    left eye."""
    near, far = settings.depth_range
    z = np.nan_to_num(depth.astype(np.float32), nan=0.0)
    mask = source_mask(left, settings.look, settings.source) & (z >= near) & (z <= far)
    rows, cols = _whole_view_budget(np.nonzero(mask), settings)
    if rows.size == 0:
        return np.zeros((0, 4))
    pixels = np.column_stack([cols, rows]).astype(np.float64)
    cam = stereo.left
    rays = cv2.undistortPoints(pixels.reshape(-1, 1, 2), cam.matrix, cam.distortion)
    zs = z[rows, cols].astype(np.float64)
    surface = np.column_stack([rays.reshape(-1, 2) * zs[:, None], zs])
    radius = half_width_px(mask)[rows, cols] * zs / float(cam.matrix[0, 0])
    centre = _to_base(_to_centre_line(surface, radius, settings.depth_range), stereo)
    return _within_budget(centre, settings.reach, settings.max_points)


def _whole_view_budget(
    indices: tuple[npt.NDArray[np.intp], ...], settings: CaneSettings
) -> tuple[npt.NDArray[np.intp], ...]:
    """The pixels ``indices`` as they are when a reach is set (every one is placed, and
    the budget spent after those out of reach are dropped); without a reach, an even
    subsample of them to ``max_points`` (the budget over the whole view: no need to
    place the pixels it drops)."""
    if settings.reach is not None:
        return indices
    step = max(1, int(np.ceil(len(indices[0]) / settings.max_points)))
    return tuple(i[::step] for i in indices)


def _within_budget(points: FloatArray, reach: float | None, max_points: int) -> FloatArray:
    """The rows of ``points`` (n, 4), base frame, within ``reach`` (m) of the base
    origin (all of them for None), then evenly subsampled to at most ``max_points``:
    the points out of reach are dropped first, so that they take none of the budget."""
    if reach is not None:
        points = points[np.linalg.norm(points[:, :3], axis=1) <= reach]
    return even_subsample(points, max_points)


def even_subsample(points: FloatArray, max_points: int) -> FloatArray:
    """Every k-th row of ``points``, k the smallest that leaves at most ``max_points``."""
    return points[:: max(1, int(np.ceil(len(points) / max_points)))]


def _to_centre_line(
    surface: FloatArray, radius: FloatArray, depth_range: tuple[float, float]
) -> FloatArray:
    """(n, 4): each surface point moved π r / 4 further along its ray, and r; points
    outside ``depth_range`` dropped."""
    keep = (surface[:, 2] >= depth_range[0]) & (surface[:, 2] <= depth_range[1])
    surface, radius = surface[keep], radius[keep]
    rays = surface / np.linalg.norm(surface, axis=1, keepdims=True)
    centre = surface + rays * (np.pi / 4.0 * radius)[:, None]
    return np.column_stack([centre, radius])


def centre_line_points(
    surface: FloatArray,
    radius: FloatArray,
    T_base_camera: FloatArray,
    depth_range: tuple[float, float],
    max_points: int,
    reach: float | None = None,
) -> FloatArray:
    """(n, 4) rows as :func:`cane_points`: the ``surface`` points (camera frame, m) of
    canes of ``radius`` (m) moved to their centre lines, those within ``depth_range``
    kept, placed by ``T_base_camera``, those within ``reach`` (m) of the base origin
    kept (None: all) and only then evenly subsampled to at most ``max_points``."""
    centre = _to_centre_line(surface, radius, depth_range)
    T = np.asarray(T_base_camera, dtype=np.float64)
    placed = np.column_stack([centre[:, :3] @ T[:3, :3].T + T[:3, 3], centre[:, 3]])
    return _within_budget(placed, reach, max_points)


def _fit_all(points: FloatArray, radius: FloatArray, settings: CaneSettings) -> list[CaneFit]:
    fits = []
    for members in split_into_curves(points, settings.search):
        coeffs = arc_length_cubic(points[members])
        cane_radius = float(np.median(radius[members]))
        evidence = settings.evidence
        if evidence is not None and not shows_a_cane(len(members), coeffs, cane_radius, evidence):
            continue
        fits.append(
            CaneFit(
                curve=PolynomialCurve(coeffs, (0.0, 1.0)),
                coeffs=coeffs,
                radius=cane_radius,
                points=points[members],
                support=len(members),
            )
        )
    return fits
