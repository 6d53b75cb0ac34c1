"""Berries without tags: a colour-and-shape detector for blackberries in BGR images.

Ripe fruit is black-purple: dark, and, unlike the dark look-alikes of a row (shadows,
mulch, an irrigation line, stones), saturated towards purple. Unripe fruit is red or
yellow-green, brighter and yellower than the leaves. Each colour class is thresholded
in HSV, closed over the gaps between drupelets and the specular highlights, and split
into connected blobs; a blob is a berry when it is compact (a fruit, not a cane or a
leaf edge) and of a fruit's size in pixels (a ripe one centred to a fraction of a
pixel, :mod:`softarm.perception.berry_centre`); where depth is given, when depth agrees
(:mod:`softarm.perception.detector.depth_check`: a fruit's metric size, in the working
range, on one fruit-sized surface).
The ripeness of a blob is the share of its pixels in the ripe colour class; the NIR
sensor in the gripper keeps the last word at the grasp.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal, cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import VisionError
from softarm.perception._inputs import bgr_image, depth_metres, instance, instance_or_default
from softarm.perception.berry_centre import RING, silhouette_centre
from softarm.perception.detector.depth_check import DepthCheck, rejection
from softarm.perception.detector.size_split import SizeSplit
from softarm.perception.detector.touching import disc_seeds, split_discs
from softarm.vision.camera_model import CameraModel

__all__ = [
    "MAX_BLOBS",
    "BerryDetection",
    "DetectorSettings",
    "Frame",
    "detect_berries",
    "detections_in_masks",
    "fruit_mask",
]

Ripeness = Literal["ripe", "unripe"]
#: The frame a detection's ``position`` is in: the camera's (``detect_berries`` with
#: depth) or the arm's base (``locate_berries``).
Frame = Literal["camera", "base"]
#: The most fruit-shaped blobs one frame gives (both colour classes together): a view of
#: a bush shows tens of fruit, not thousands. Beyond it the largest are kept (in their
#: usual order), so that a frame of thousands of fruit-sized specks (a patterned sheet,
#: a shaded net) costs a bounded time, above all in the stereo match that follows.
MAX_BLOBS = 500
#: The most ripe blobs a frame's centres are refined for (the largest; a bush view holds
#: tens of fruit): :func:`~softarm.perception.berry_centre.silhouette_centre` costs about
#: a millisecond a blob.
MAX_REFINED = 64
#: ...and only up to this radius (px): a drupelet's specular highlight, about a ninth of
#: the fruit's radius, is then within the detector's 3x3 blur. On a larger fruit (C2's
#: close-up, 20-30 px) highlights on the lit edge read as background and the refined
#: centre leans away from the light (0.6 px against the mask's 0.3 on C2 at the grasp).
MAX_REFINED_RADIUS = 14.0
#: The least radius (px, the distance map's height) of a second fruit in a colour blob:
#: that of a fruit of the least area (40 px: 3.6 px), less a pixel of ragged outline.
SEED_RADIUS = 2.5
# What OpenCV returns for a uint8 image (its stubs say any number array).
_U8 = npt.NDArray[np.uint8]
_Contour = npt.NDArray[np.int32]


@dataclass(frozen=True)
class DetectorSettings:
    """Thresholds of the detector (OpenCV HSV: H in [0, 180), S and V in [0, 255]).

    Tuned on rendered bushes of seeds 0–4 only (docs/perception.md).
    """

    ripe_hue: tuple[int, int] = (110, 176)
    ripe_min_saturation: int = 80
    ripe_max_value: int = 80
    red_hue: int = 10  # red: H <= red_hue or H >= 180 - red_hue
    green_hue: tuple[int, int] = (27, 45)
    unripe_min_saturation: int = 110
    unripe_min_value: int = 60
    min_area_px: int = 40
    min_solidity: float = 0.75
    max_elongation: float = 2.6
    #: The network's instances: fruit that touch split at the necks of their part's
    #: distance map (:mod:`softarm.perception.detector.touching`) where True, else at the
    #: network's centre heatmap peaks. An option: on the held-out sets it found more ripe
    #: fruit in every look of the row but cost precision in the bush world
    #: (docs/perception-candidates.md, "Splitting touching fruit").
    split_touching: bool = False
    #: The colour rule's ripe blobs split the same way before the shape tests, where
    #: True (an option: more ripe fruit found, precision lost in sun and dusk).
    split_colour_blobs: bool = False
    #: Where a depth image is given, a network instance larger than the largest fruit at
    #: its depth is cut into the fruit its area and shape say it holds before the depth
    #: check, instead of being dropped whole (:mod:`softarm.perception.detector.size_split`;
    #: an option: docs/perception-candidates.md, "Splitting merged fruit by the size depth
    #: expects": ripe recall up in every look of the row, localisation down).
    split_by_size: bool = False
    #: The colour rule's ripe blobs cut the same way before the shape tests, where True
    #: (an option: more ripe fruit found, precision lost in backlight and dusk).
    split_colour_by_size: bool = False
    #: What a depth image must say of a detection where one is given
    #: (:mod:`softarm.perception.detector.depth_check`); None: depth only places it.
    depth_check: DepthCheck | None = field(default_factory=DepthCheck)


@dataclass(frozen=True)
class BerryDetection:
    """One berry in an image: ``center`` (x, y) px, equivalent ``radius`` px, ``box``
    (x, y, w, h), ``score`` in [0, 1], ``ripeness`` and its ``probability``;
    ``position`` (3,) m, in the frame ``frame`` names, and ``radius_m``, the fruit's
    radius as its outline shows it, when the berry was placed.

    ``mask`` is the berry's pixels over its box only (bool, (h, w)), not over the whole
    frame: its pixel (r, c) is the image's (r + ``mask_offset[1]``, c +
    ``mask_offset[0]``), and :meth:`mask_window` cuts it to any window of the image.
    ``frame`` is ``"camera"`` for :func:`detect_berries` (positions from its depth image,
    in the camera frame) and ``"base"`` for
    :func:`~softarm.perception.stereo.locate_berries` (the arm's base frame).
    """

    center: tuple[float, float]
    radius: float
    box: tuple[int, int, int, int]
    mask: npt.NDArray[np.bool_] = field(repr=False)  # a repr of a few lines, not pixels
    score: float
    ripeness: Ripeness
    probability: float
    position: FloatArray | None = None
    radius_m: float | None = None
    #: (x, y) of the image pixel under ``mask[0, 0]``: (0, 0) for a full-frame mask.
    mask_offset: tuple[int, int] = (0, 0)
    frame: Frame = "camera"

    def mask_window(self, x0: int, y0: int, x1: int, y1: int) -> npt.NDArray[np.bool_]:
        """The berry's pixels on image columns ``x0:x1`` and rows ``y0:y1`` as an
        (y1 - y0, x1 - x0) bool array, False beyond the mask."""
        out = np.zeros((y1 - y0, x1 - x0), bool)
        ox, oy = self.mask_offset
        h, w = self.mask.shape
        ax0, ay0, ax1, ay1 = max(x0, ox), max(y0, oy), min(x1, ox + w), min(y1, oy + h)
        if ax0 < ax1 and ay0 < ay1:
            out[ay0 - y0 : ay1 - y0, ax0 - x0 : ax1 - x0] = self.mask[
                ay0 - oy : ay1 - oy, ax0 - ox : ax1 - ox
            ]
        return out

    def full_mask(self, shape: tuple[int, ...]) -> npt.NDArray[np.bool_]:
        """The berry's pixels over a whole image of ``shape`` (H, W, ...): for a
        comparison with other full-frame masks (0.9 MB at 1280 x 720, so not kept)."""
        return self.mask_window(0, 0, shape[1], shape[0])

    @property
    def ripe_vote(self) -> float:
        """This detection's vote for ripe, in [0, 1]: ``probability`` when it says ripe,
        its complement when it says unripe (what the bush map adds up over sightings)."""
        return self.probability if self.ripeness == "ripe" else 1.0 - self.probability


def ripe_by_votes(ripe_votes: float, sightings: int) -> bool:
    """Ripe when at least half of a fruit's ``sightings`` said so (summed
    :attr:`BerryDetection.ripe_vote`); the NIR sensor decides at the grasp.

    A tie (``ripe_votes`` exactly half of ``sightings``, compared as summed) is ripe: the
    NIR sensor has the last word, so a tie costs at most one approach, where calling it
    unripe would leave a fruit that may be ripe unpicked without a look."""
    return ripe_votes >= 0.5 * sightings


def detect_berries(
    image: npt.NDArray[np.uint8],
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None = None,
    settings: DetectorSettings | None = None,
) -> list[BerryDetection]:
    """The berries in ``image`` (BGR uint8, as OpenCV reads it) seen by ``camera``; at
    most :data:`MAX_BLOBS`.

    ``image`` must be the size of ``camera.image_size`` when the camera has one (a
    frame of another size would be read through the wrong intrinsics).
    ``depth`` (H, W) float metres aligned with ``image`` (0 or NaN unknown) adds each
    berry's ``position`` in the camera frame (``frame`` "camera") and a check of its
    physical size. A uint16 depth in millimetres (as ``softarm dataset`` writes it) is
    refused: divide it by 1000 first.

    Raises:
        VisionError: ``image`` is not an (H, W, 3) uint8 array of at most
            :data:`~softarm.perception._inputs.MAX_FRAME_PIXELS` pixels and of the
            camera's image size, or ``depth`` is not a float array of its height and
            width.
        InputError: ``camera`` is not a CameraModel, or ``settings`` not a
            DetectorSettings.
    """
    s = instance_or_default(settings, DetectorSettings, "settings")
    _check(image, depth, instance(camera, CameraModel, "camera"))
    blurred = cast(_U8, cv2.GaussianBlur(image, (3, 3), 0))
    hsv = cast(_U8, cv2.cvtColor(blurred, cv2.COLOR_BGR2HSV))
    ripe, unripe = _colour_masks(hsv, s)
    found = detections_in_masks(ripe, unripe, camera, depth, s)
    # The harvest steers by ripe fruit's centres (an unripe one's only places it in the
    # map); the largest first, at most MAX_REFINED: a frame of specks costs a bound. A
    # fruit placed by depth keeps the centre its position was found on, and a large one
    # its mask's (MAX_REFINED_RADIUS).
    ripe_ones = [
        k for k, d in enumerate(found)
        if d.ripeness == "ripe" and d.position is None and d.radius <= MAX_REFINED_RADIUS
    ]  # fmt: skip
    for k in sorted(ripe_ones, key=lambda k: -found[k].radius)[:MAX_REFINED]:
        found[k] = _centred(found[k], blurred)
    return found


def _centred(det: BerryDetection, colour: npt.NDArray[np.uint8]) -> BerryDetection:
    """``det`` with its centre at its silhouette's, edge pixels counted by how much of
    them is fruit (:func:`~softarm.perception.berry_centre.silhouette_centre`: the
    mask's centroid leans towards the darker background by a few tenths of a pixel)."""
    x, y, w, h = det.box
    pad = RING[1] + 1
    x0, y0 = max(x - pad, 0), max(y - pad, 0)
    x1, y1 = min(x + w + pad, colour.shape[1]), min(y + h + pad, colour.shape[0])
    mask = det.mask_window(x0, y0, x1, y1)
    centre = silhouette_centre(mask, colour[y0:y1, x0:x1], (x0, y0), det.center)
    return replace(det, center=centre)


def detections_in_masks(
    ripe: npt.NDArray[np.uint8],
    unripe: npt.NDArray[np.uint8],
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None,
    s: DetectorSettings,
) -> list[BerryDetection]:
    """The berries of the ``ripe`` and ``unripe`` pixel masks ((H, W) uint8, 0/255),
    whatever made them (the colour thresholds, a pixel network): closed, split into
    fruit-shaped blobs (at most :data:`MAX_BLOBS`), each placed and sized (the shape
    stage every detector shares). Arguments and errors as :func:`detect_berries`."""
    _check_masks(ripe, unripe)
    instance(camera, CameraModel, "camera")
    instance(s, DetectorSettings, "settings")
    depth = depth_metres(depth, ripe.shape)
    # Only the ripe class is split: the unripe one holds the yellow-green canes, whose
    # strips split into fruit-sized pieces at every knot and crossing.
    sizes = None
    if depth is not None and s.split_colour_by_size and s.depth_check is not None:
        sizes = SizeSplit(depth, camera.focal, s.depth_check, s.depth_check.outline_px)
    ripe_blobs = _blobs(_close(ripe), s, s.split_colour_blobs, sizes)
    blobs = ripe_blobs + _blobs(_close(unripe), s, False)
    out = []
    for blob in _capped(blobs):
        det = _detection(blob, ripe, unripe, camera, depth, s)
        if det is not None:
            out.append(det)
    return out


def _check(image: object, depth: object, camera: CameraModel | None = None) -> None:
    """``image`` a BGR frame (of ``camera``'s image size when it has one) and ``depth``
    None or float metres of its size."""
    checked = bgr_image(image, "image")
    metres = depth_metres(depth, checked.shape)
    # NaN, 0 and +-inf are unknown (ROS REP 118's float depth); a negative depth is no
    # depth at all: a wrong unit or sign, refused rather than read as "unknown".
    if metres is not None:
        negative = metres < 0
        if negative.any() and np.isfinite(metres[negative]).any():
            raise VisionError("depth holds negative values: give metres in front of the camera")
    if camera is not None:
        bgr_image(checked, "image", camera.image_size)


def _check_masks(ripe: object, unripe: object) -> None:
    for name, mask in (("ripe", ripe), ("unripe", unripe)):
        if not isinstance(mask, np.ndarray) or mask.dtype != np.uint8 or mask.ndim != 2:
            raise VisionError(f"{name} must be an (H, W) uint8 mask, got {type(mask).__name__}")
    assert isinstance(ripe, np.ndarray) and isinstance(unripe, np.ndarray)
    if ripe.shape != unripe.shape:
        raise VisionError(f"ripe {ripe.shape} and unripe {unripe.shape} masks differ in shape")


def _capped(
    blobs: list[tuple[npt.NDArray[np.int32], float]],
) -> list[npt.NDArray[np.int32]]:
    """The contours of ``blobs`` (contour, area), the MAX_BLOBS largest kept in their
    order when there are more."""
    if len(blobs) > MAX_BLOBS:
        order = sorted(range(len(blobs)), key=lambda k: -blobs[k][1])
        keep = set(order[:MAX_BLOBS])
        blobs = [b for k, b in enumerate(blobs) if k in keep]
    return [c for c, _ in blobs]


def fruit_mask(
    image: npt.NDArray[np.uint8], settings: DetectorSettings | None = None
) -> npt.NDArray[np.uint8]:
    """The pixels (0/255) of either fruit colour class in a BGR image, closed over the
    drupelet gaps: the silhouettes that stereo matches (:mod:`softarm.perception.stereo`)."""
    s = instance_or_default(settings, DetectorSettings, "settings")
    bgr_image(image, "image")
    hsv = cast(_U8, cv2.cvtColor(cv2.GaussianBlur(image, (3, 3), 0), cv2.COLOR_BGR2HSV))
    ripe, unripe = _colour_masks(hsv, s)
    return _close(cast(_U8, cv2.bitwise_or(ripe, unripe)))


def _colour_masks(
    hsv: npt.NDArray[np.uint8], s: DetectorSettings
) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
    """(ripe, unripe) binary masks (0/255)."""
    h, sat, val = hsv[..., 0], hsv[..., 1], hsv[..., 2]
    ripe = (
        (h >= s.ripe_hue[0]) & (h <= s.ripe_hue[1])
        & (sat >= s.ripe_min_saturation) & (val <= s.ripe_max_value) & (val > 0)
    )  # fmt: skip
    bright = (sat >= s.unripe_min_saturation) & (val >= s.unripe_min_value)
    red = (h <= s.red_hue) | (h >= 180 - s.red_hue)
    green = (h >= s.green_hue[0]) & (h <= s.green_hue[1])
    unripe = bright & (red | green)
    return ripe.astype(np.uint8) * 255, unripe.astype(np.uint8) * 255


def _close(mask: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint8]:
    """Bridge the gaps between drupelets and the highlights on them."""
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5))
    return cast(_U8, cv2.morphologyEx(mask, cv2.MORPH_CLOSE, kernel))


def _blobs(
    mask: npt.NDArray[np.uint8], s: DetectorSettings, split: bool, sizes: SizeSplit | None = None
) -> list[tuple[npt.NDArray[np.int32], float]]:
    """Outer contours of the compact blobs of ``mask``, holes filled, with their areas;
    with ``split``, every blob first divided into one per fruit it holds (a cluster of
    fruit is neither compact nor disc-like as a whole), each piece then tested; with
    ``sizes``, a blob larger than a fruit at its depth first cut into the fruit it
    holds (:mod:`softarm.perception.detector.size_split`), each piece then as a blob."""
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if sizes is not None:
        contours = [p for c in contours for p in sizes.contours(cast(_Contour, c))]
    out = []
    for found in contours:
        c = cast(_Contour, found)
        if not split:
            if _fruit_shaped(c, s):
                out.append((c, float(cv2.contourArea(c))))
            continue
        pieces = _touching_split(c, s)
        out.extend((p, float(cv2.contourArea(p))) for p in pieces if _fruit_shaped(p, s))
    return out


def _fruit_shaped(c: _Contour, s: DetectorSettings) -> bool:
    """A blob of a fruit's area that is compact (solid, not elongated)."""
    area = cv2.contourArea(c)
    if area < s.min_area_px or len(c) < 5:
        return False
    hull = cv2.contourArea(cv2.convexHull(c))
    (_, _), (a, b), _ = cv2.fitEllipse(c)
    if hull <= 0 or area / hull < s.min_solidity:
        return False
    return bool(max(a, b) <= s.max_elongation * max(min(a, b), 1e-6))


def _touching_split(contour: _Contour, s: DetectorSettings) -> list[_Contour]:
    """``contour``'s blob as one outline per fruit it holds (itself when one):
    :mod:`softarm.perception.detector.touching`, on the blob filled. Only a blob that
    could hold two fruit of the least area is looked at (the cost is its box's)."""
    if cv2.contourArea(contour) < 2 * s.min_area_px:
        return [contour]
    bx, by, bw, bh = cv2.boundingRect(contour)
    filled = np.zeros((bh, bw), np.uint8)
    cv2.drawContours(filled, [contour], -1, 1, thickness=cv2.FILLED, offset=(-bx, -by))
    blob = filled > 0
    seeds = disc_seeds(blob, SEED_RADIUS)
    if len(seeds) < 2:
        return [contour]
    out: list[_Contour] = []
    for piece in split_discs(blob, seeds):
        found, _ = cv2.findContours(
            piece.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE, offset=(bx, by)
        )
        out.extend(cast(list[_Contour], list(found)))
    return out


def _detection(
    contour: npt.NDArray[np.int32],
    ripe: npt.NDArray[np.uint8],
    unripe: npt.NDArray[np.uint8],
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None,
    s: DetectorSettings,
) -> BerryDetection | None:
    # The blob's own box only: a full-frame mask per blob cost 0.9 MB and a full-frame
    # pass each at 1280 x 720, 3.3 GB and 16 s for a frame of 3,600 specks.
    bx, by, bw, bh = cv2.boundingRect(contour)
    mask = np.zeros((bh, bw), np.uint8)
    cv2.drawContours(mask, [contour], -1, 255, thickness=cv2.FILLED, offset=(-bx, -by))
    inside = mask > 0
    box = (slice(by, by + bh), slice(bx, bx + bw))
    n_ripe = int(np.count_nonzero(ripe[box][inside]))
    n_unripe = int(np.count_nonzero(unripe[box][inside]))
    p_ripe = n_ripe / max(n_ripe + n_unripe, 1)
    m = cv2.moments(mask, binaryImage=True)
    cx, cy = bx + m["m10"] / m["m00"], by + m["m01"] / m["m00"]
    radius = float(np.sqrt(m["m00"] / np.pi))
    position = None
    if depth is not None:
        if s.depth_check is not None and rejection(
            inside, radius, depth[box], camera.focal, s.depth_check
        ):
            return None
        position = _position(inside, (cx, cy), radius, camera, depth[box])
    purity = (n_ripe + n_unripe) / m["m00"]
    solidity = m["m00"] / max(cv2.contourArea(cv2.convexHull(contour)), 1.0)
    ripeness: Ripeness = "ripe" if p_ripe >= 0.5 else "unripe"
    return BerryDetection(
        center=(float(cx), float(cy)),
        radius=radius,
        box=(int(bx), int(by), int(bw), int(bh)),
        mask=inside,
        score=float(np.clip(purity * solidity, 0.0, 1.0)),
        ripeness=ripeness,
        probability=float(p_ripe if ripeness == "ripe" else 1.0 - p_ripe),
        position=position,
        radius_m=None
        if position is None
        else radius * float(np.linalg.norm(position)) / camera.focal,
        mask_offset=(int(bx), int(by)),
    )


def _position(
    inside: npt.NDArray[np.bool_],
    center: tuple[float, float],
    radius_px: float,
    camera: CameraModel,
    depth: npt.NDArray[np.floating],
) -> FloatArray | None:
    """The berry's centre in the camera frame (``depth``: the box ``inside`` covers): the
    median depth of its visible surface,
    pushed back by two thirds of its radius (the mean depth of a sphere's visible cap
    under orthographic weighting), along the ray through its image centre."""
    z = depth[inside]
    z = z[np.isfinite(z) & (z > 0)]
    if z.size == 0:
        return None
    surface = float(np.median(z))
    ray = camera.normalize(np.array([center]))[0]
    direction = np.array([ray[0], ray[1], 1.0])
    radius_m = radius_px * surface / camera.focal
    centre_z = surface + 2.0 / 3.0 * radius_m
    return direction * centre_z
