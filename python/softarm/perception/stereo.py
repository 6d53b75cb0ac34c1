"""Berry positions from C1's stereo pair.

Both images are rectified and the berries are detected in the rectified left image. Each
one is matched along its rows in the rectified right image by its silhouette: the fruit
colour mask of each eye (:func:`~softarm.perception.berries.fruit_mask`), blurred, with
the berry's own mask as the template's support, and again by its grey levels; each match
is refined to a fraction of a pixel by a parabola through the best cost and its two
neighbours. The two err differently: the outline by the drupelets that form it in each
eye, the shading by the background behind the fruit and the highlights on it (which move
with the eye). Their mean is taken where they agree within a pixel; where they do not,
the match is on a neighbour or on a fruit half hidden in one eye, and the berry is left
without a position for a later look (on the diagnosis bushes 200–219: p95 8.6 mm with
the outline alone, 6.9 with the shading alone, 6.0 with both, 93 % localised). Where
one cue has no unique match, the other's stands if the first one's cost does not
contradict it; where both match within two pixels but not one, the shading's stands
(diagnosed on harvest bushes 736, 739 and 750–757, where whole berries in view were
otherwise never mapped, look after look). Where they disagree otherwise, the outline's
stands if the fruit's outline is alone: no other detected fruit beside it on its rows,
and the two eyes' silhouettes alike at the match (the shading's template holds the
row's leaves, canes and sky around the fruit's edge, at other depths; on the diagnosis
rows 90120–90125 this places 37 of the 48 ripe berries of C1's first look, against 16).
With f ≈ 900 px and B = 0.12 m a pixel of disparity is about 13 mm of depth at 1.2 m.
The silhouette of a round fruit is its equator, so the triangulated point is taken as the
centre. The drupelets that form the outline differ between the two eyes, which leaves
about half a pixel of disparity noise per berry (±5 mm at 1 m). A ripe berry is
triangulated at the mean of its two eyes' centres (:mod:`softarm.perception.two_eyes`),
so that its direction from the baseline's middle, which C1's ray to it keeps, averages
the eyes' centre errors while the disparity's moves it along that ray only.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.perception._inputs import bgr_image, instance
from softarm.perception.berries import (
    BerryDetection,
    DetectorSettings,
)
from softarm.perception.detector.choice import detect_berries, fruit_mask  # the chosen detector
from softarm.perception.two_eyes import mean_centre
from softarm.vision.camera_model import CameraModel
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["locate_berries", "match_disparity"]

#: Rows (px) read above and below the berries.
BAND_MARGIN = 8
#: The blur (px) of the silhouettes: the edge spread over a few pixels gives the match
#: a smooth cost, whose parabola vertex is the sub-pixel disparity.
SILHOUETTE_BLUR = 1.0
#: How far (px) the outline's and the shading's disparities may differ.
AGREEMENT = 1.0
#: Beyond AGREEMENT and up to this far (px) apart, the shading's disparity stands alone.
SHADING_LEAD = 2.0
#: The fruit's width (m): 1.5–2.5 cm across, with a margin either side.
FRUIT_ACROSS = (0.013, 0.032)
#: How much of the template's support the two eyes' silhouettes must share (their
#: intersection over union there) for the outline's match to stand against the shading's.
OUTLINE_OVERLAP = 0.6
#: How much better (as a share of the cost) the best match must be than any other.
UNIQUENESS = 0.15
#: Depths (m) searched along the rows: the disparity range f B / z.
DEPTH_RANGE = (0.4, 2.5)


def locate_berries(
    left: npt.NDArray[np.uint8],
    right: npt.NDArray[np.uint8],
    stereo: StereoCamera,
    settings: DetectorSettings | None = None,
) -> list[BerryDetection]:
    """The berries of a stereo pair with ``position`` (3,) in the BASE frame (each
    detection's ``frame`` is ``"base"``); ``center``, ``box`` and ``mask`` refer to the
    rectified left image. A berry that cannot be matched in the right image is returned
    without a position. At most :data:`~softarm.perception.berries.MAX_BLOBS`.

    Raises:
        VisionError: ``left`` or ``right`` is not an (H, W, 3) uint8 BGR image of its
            eye's calibrated ``image_size`` (a frame of another size is refused, not
            cropped or scaled: the calibration would place every berry wrongly).
        InputError: ``stereo`` is not a StereoCamera, or ``settings`` not a
            DetectorSettings.
    """
    instance(stereo, StereoCamera, "stereo")
    if settings is not None:
        instance(settings, DetectorSettings, "settings")
    bgr_image(left, "left", stereo.left.image_size)
    bgr_image(right, "right", stereo.right.image_size)
    rect = stereo.rectification
    mx, my = rect.maps[0]
    L = cast(npt.NDArray[np.uint8], cv2.remap(left, mx, my, cv2.INTER_LINEAR))
    rect_cam = CameraModel(rect.P1[:3, :3], np.zeros(5), rect.size)  # no distortion
    detections = detect_berries(L, rect_cam, settings=settings)
    if not detections:
        return []
    rows = _band(detections, L.shape[0])
    R = _rectified_rows(right, rect.maps[1], rows, L.shape)
    fruit_l, fruit_r = (_fruit(img, rows, settings) for img in (L, R))
    sil_l, sil_r = (_blurred(m, rows) for m in (fruit_l, fruit_r))
    right_colour = cast(npt.NDArray[np.uint8], cv2.GaussianBlur(R, (3, 3), 0))  # as the detector's
    grey_l, grey_r = (_grey(img, rows) for img in (L, R))
    d_lo = rect.focal * rect.baseline / DEPTH_RANGE[1]
    d_hi = rect.focal * rect.baseline / DEPTH_RANGE[0]
    out = []
    for det in detections:
        cues = _Cues((sil_l, sil_r), (grey_l, grey_r), det, (d_lo, d_hi), detections)
        d = cues.disparity()
        position = radius_m = None
        if d is not None and _plausible(d, det.radius, rect.baseline):
            # The mean of the two eyes' centres: C1's ray from the baseline's middle.
            px = mean_centre(det, d, right_colour, (fruit_r * 255).astype(np.uint8))
            centre = rect.triangulate(np.array([px]), np.array([d]))[0]
            position = (stereo.T_base_left @ np.append(centre, 1.0))[:3]
            radius_m = det.radius * float(np.linalg.norm(centre)) / rect.focal
        out.append(replace(det, position=position, radius_m=radius_m, frame="base"))
    return out


def match_disparity(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    det: BerryDetection,
    disparity_range: tuple[float, float],
) -> float | None:
    """The disparity (px) of ``det`` between rectified grey images, or None when the
    search window leaves the image or the match is flat."""
    curve = _cost_curve(left, right, det, disparity_range)
    if curve is None:
        return None
    cost, x0, s0 = curve
    k = int(np.argmin(cost))
    if k == 0 or k == cost.size - 1 or not _unique(cost, k):
        return None
    a, b, c = cost[k - 1], cost[k], cost[k + 1]
    curvature = a - 2 * b + c
    if curvature <= 0:
        return None
    sub = 0.5 * (a - c) / curvature  # the parabola's vertex, in [-0.5, 0.5]
    x_right = s0 + k + sub
    return float(x0 - x_right)


def _cost_curve(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    det: BerryDetection,
    disparity_range: tuple[float, float],
) -> tuple[npt.NDArray[np.float32], int, int] | None:
    """The masked template's squared-difference cost along the rows of the right
    image, with the template's left column ``x0`` and the strip's ``s0`` (a cost index
    k is the disparity ``x0 - s0 - k``); None when the window leaves the image."""
    x0, y0, x1, y1 = _window(det)
    height, width = left.shape
    if x0 < 0 or y0 < 0 or x1 > width or y1 > height:
        return None
    template = left[y0:y1, x0:x1]
    mask = _support(det, (x0, y0, x1, y1)).astype(np.float32)
    lo = max(int(np.floor(disparity_range[0])), 0)
    hi = int(np.ceil(disparity_range[1]))
    s0 = max(x0 - hi, 0)
    s1 = x1 - lo
    if s1 - s0 < (x1 - x0) + 2:
        return None
    strip = right[y0:y1, s0:s1]
    cost = cv2.matchTemplate(strip, template, cv2.TM_SQDIFF, mask=mask)[0]
    return cost, x0, s0


def _window(det: BerryDetection) -> tuple[int, int, int, int]:
    """The template's window (x0, y0, x1, y1): the berry's box with 2 px either side."""
    x, y, w, h = det.box
    pad = 2
    return x - pad, y - pad, x + w + pad, y + h + pad


def _support(det: BerryDetection, window: tuple[int, int, int, int]) -> npt.NDArray[np.uint8]:
    """The template's support over ``window``: the berry's mask dilated by a pixel, so
    that the silhouette's edge is in it (0/1)."""
    mask = det.mask_window(*window).astype(np.uint8)
    return cast(npt.NDArray[np.uint8], cv2.dilate(mask, np.ones((3, 3), np.uint8)))


def _cost_allows(
    left: npt.NDArray[np.float32],
    right: npt.NDArray[np.float32],
    det: BerryDetection,
    disparity_range: tuple[float, float],
    disparity: float,
) -> bool:
    """Whether a cue that found no unique match of its own (``left``, ``right``: its
    images) does not contradict the other cue's ``disparity``: its cost within a pixel
    of it is within UNIQUENESS of its best (a dark fruit on a dark ground matches its
    shading almost anywhere along the rows; a match on a neighbour would cost it more)."""
    curve = _cost_curve(left, right, det, disparity_range)
    if curve is None:
        return False
    cost, x0, s0 = curve
    k = round(x0 - disparity - s0)
    if k < 1 or k >= cost.size - 1:
        return False
    return float(cost[k - 1 : k + 2].min()) <= (1.0 + UNIQUENESS) * float(cost.min())


class _Cues:
    """The outline's and the shading's matches of one berry, and the disparity they
    give together (:meth:`disparity`)."""

    def __init__(
        self,
        outline: tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]],
        shading: tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]],
        det: BerryDetection,
        disparity_range: tuple[float, float],
        detections: Sequence[BerryDetection] = (),
    ) -> None:
        self.outline, self.shading, self.det, self.range = outline, shading, det, disparity_range
        self.neighbours = [d for d in detections if d is not det and _beside(det, d)]
        self.by_outline = match_disparity(*outline, det, disparity_range)
        self.by_shading = match_disparity(*shading, det, disparity_range)

    def disparity(self) -> float | None:
        """Their mean where they agree within AGREEMENT px. Where both match but differ
        by up to SHADING_LEAD px, the shading's stands: alone it is the better cue (p95
        6.9 against 8.6 mm on the diagnosis bushes 200–219), and a match on a neighbour
        lies farther off. Where one cue has no unique match of its own, the other's
        stands if that cue's cost does not contradict it (:func:`_cost_allows`): a dark
        fruit on a dark ground leaves the shading flat, a fruit whose drupelets differ
        in the two eyes the outline. The outline's match stands against the shading's
        too where the fruit's outline is alone (:meth:`_outline_alone`). Else None: a
        later look may place it."""
        a, g = self.by_outline, self.by_shading
        agreed = _agreed(a, g)
        if agreed is not None:
            return agreed
        if a is not None and g is not None and abs(a - g) <= SHADING_LEAD:
            return g
        if a is not None:
            allowed = g is None and _cost_allows(*self.shading, self.det, self.range, a)
            return a if allowed or self._outline_alone(a) else None
        if g is not None:
            return g if _cost_allows(*self.outline, self.det, self.range, g) else None
        return None

    def _outline_alone(self, disparity: float) -> bool:
        """Whether the outline's match at ``disparity`` needs no word from the shading:
        no other detected fruit beside the berry (:func:`_beside`), whose image in the
        right eye could take the match, and the two eyes' silhouettes sharing
        OUTLINE_OVERLAP of the template's support there (a fruit that a leaf hides
        differently in the two eyes has two outlines, and the match slides between
        them: on test bush 300 a berry 2.9 px off, 0.41 shared). Against the row's
        leaves, canes and sky, which the shading's template holds around the fruit's
        edge at other depths, the shading vetoed 21 outline matches within 1.5 px of the
        truth on the diagnosis rows 90120–90125 (C1's first look); 20 stand by this."""
        if self.neighbours:
            return False
        x0, y0, x1, y1 = _window(self.det)
        shift = round(disparity)
        sil_l, sil_r = self.outline
        if x0 - shift < 0 or x1 > sil_l.shape[1] or y0 < 0 or y1 > sil_l.shape[0]:
            return False
        support = _support(self.det, (x0, y0, x1, y1)) > 0
        left = (sil_l[y0:y1, x0:x1] > 0.5) & support
        right = (sil_r[y0:y1, x0 - shift : x1 - shift] > 0.5) & support
        union = int((left | right).sum())
        return union > 0 and (left & right).sum() >= OUTLINE_OVERLAP * union


def _beside(det: BerryDetection, other: BerryDetection) -> bool:
    """Whether ``other`` lies on ``det``'s rows within one of ``det``'s widths of its box
    either side: there its image in the right eye could take ``det``'s outline match."""
    x, y, w, h = det.box
    ox, oy, ow, oh = other.box
    rows = min(y + h, oy + oh) > max(y, oy)
    return rows and ox < x + 2 * w and ox + ow > x - w


def _agreed(by_outline: float | None, by_shading: float | None) -> float | None:
    """The mean of the two disparities when they agree within AGREEMENT px, else None:
    the outline and the shading of a fruit err differently (the drupelets on the
    outline, the background and highlights in the shading), and a match where they
    disagree is on a neighbour or half hidden in one eye."""
    if by_outline is None or by_shading is None or abs(by_outline - by_shading) > AGREEMENT:
        return None
    return 0.5 * (by_outline + by_shading)


def _band(detections: list[BerryDetection], height: int) -> slice:
    """The rows the matching reads: those of the berries, with a margin."""
    top = min(d.box[1] for d in detections) - BAND_MARGIN
    bottom = max(d.box[1] + d.box[3] for d in detections) + BAND_MARGIN
    return slice(max(top, 0), min(bottom, height))


def _rectified_rows(
    image: npt.NDArray[np.uint8],
    maps: tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]],
    rows: slice,
    shape: tuple[int, ...],
) -> npt.NDArray[np.uint8]:
    """The rectified ``image`` on ``rows`` only, black elsewhere (the right eye is read
    only where the berries' rows are)."""
    out = np.zeros(shape, np.uint8)
    out[rows] = cv2.remap(image, maps[0][rows], maps[1][rows], cv2.INTER_LINEAR)
    return out


def _grey(image: npt.NDArray[np.uint8], rows: slice) -> npt.NDArray[np.float32]:
    out = np.zeros(image.shape[:2], np.float32)
    out[rows] = cv2.cvtColor(image[rows], cv2.COLOR_BGR2GRAY)
    return out


def _blurred(fruit: npt.NDArray[np.float32], rows: slice) -> npt.NDArray[np.float32]:
    """The silhouettes the eyes match: the fruit pixels of ``rows`` blurred by
    SILHOUETTE_BLUR."""
    out = np.zeros_like(fruit)
    out[rows] = cv2.GaussianBlur(fruit[rows], (0, 0), SILHOUETTE_BLUR)
    return out


def _fruit(
    image: npt.NDArray[np.uint8], rows: slice, settings: DetectorSettings | None
) -> npt.NDArray[np.float32]:
    """The fruit pixels of a rectified image's ``rows`` as a [0, 1] image; blurred, they
    are the silhouettes the two eyes match, so that neither the background behind a
    fruit nor the highlights on it (which move with the eye) pull the match."""
    out = np.zeros(image.shape[:2], np.float32)
    out[rows] = fruit_mask(image[rows], settings).astype(np.float32) / 255.0
    return out


def _plausible(disparity: float, radius_px: float, baseline: float) -> bool:
    """The stereo depth f B / d agrees with the depth the fruit's apparent size allows,
    f D / (2 r) for a fruit D across in FRUIT_ACROSS (the focal lengths cancel: the
    test is on B / d against D / 2r). A half-hidden fruit looks smaller, which only
    moves its size-depth farther: the near bound holds for it too, and the far bound
    allows a fruit seen at half its width. Diagnosed on bushes 203 and 208, where a
    match on another dark fruit along the rows put a berry 0.3 m off."""
    z_over_f = baseline / disparity
    return FRUIT_ACROSS[0] / (2 * radius_px) <= z_over_f <= FRUIT_ACROSS[1] / radius_px


def _unique(cost: npt.NDArray[np.float32], k: int) -> bool:
    """The best match must beat every match more than two pixels from it by
    UNIQUENESS (StereoSGBM's uniqueness ratio): another dark fruit on the same rows, or
    a berry seen whole in one eye and half hidden in the other, can match almost as
    well, and a wrong match is a gross error (tens of centimetres), not a small one."""
    others = np.concatenate([cost[: max(k - 2, 0)], cost[k + 3 :]])
    return others.size == 0 or float(cost[k]) < (1.0 - UNIQUENESS) * float(others.min())


def to_camera(points_base: FloatArray, T_base_camera: FloatArray) -> FloatArray:
    """(N, 3) base-frame points in a camera's frame."""
    R, t = T_base_camera[:3, :3], T_base_camera[:3, 3]
    return (np.asarray(points_base) - t) @ R
