"""Berries without tags: a colour-and-shape detector for blackberries in BGR images.

Ripe fruit is black-purple: dark, and, unlike the dark look-alikes of a row (shadows,
mulch, an irrigation line, stones), saturated towards purple. Unripe fruit is red or
yellow-green, brighter and yellower than the leaves. Each colour class is thresholded
in HSV, closed over the gaps between drupelets and the specular highlights, and split
into connected blobs; a blob is a berry when it is compact (a fruit, not a cane or a
leaf edge) and of a fruit's size (in pixels, or in metres when depth is given).
The ripeness of a blob is the share of its pixels in the ripe colour class; the NIR
sensor in the gripper keeps the last word at the grasp.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import VisionError
from softarm.vision.camera_model import CameraModel

__all__ = [
    "BerryDetection",
    "DetectorSettings",
    "detect_berries",
    "detections_in_masks",
    "fruit_mask",
]

Ripeness = Literal["ripe", "unripe"]
# What OpenCV returns for a uint8 image (its stubs say any number array).
_U8 = npt.NDArray[np.uint8]


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
    #: Physical size (m) of a fruit's equivalent diameter when depth is known.
    diameter_m: tuple[float, float] = (0.008, 0.04)


@dataclass(frozen=True)
class BerryDetection:
    """One berry in an image: ``center`` (x, y) px, equivalent ``radius`` px, ``box``
    (x, y, w, h), ``mask`` (H, W) bool, ``score`` in [0, 1], ``ripeness`` and its
    ``probability``; ``position`` (3,) in the camera frame (m) and ``radius_m``, the
    fruit's radius as its outline shows it, when depth was given."""

    center: tuple[float, float]
    radius: float
    box: tuple[int, int, int, int]
    mask: npt.NDArray[np.bool_]
    score: float
    ripeness: Ripeness
    probability: float
    position: FloatArray | None = None
    radius_m: float | None = None

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
    """The berries in ``image`` (BGR uint8, as OpenCV reads it) seen by ``camera``.

    ``depth`` (H, W) metres aligned with ``image`` (0 or NaN unknown) adds each
    berry's ``position`` in the camera frame and a check of its physical size.

    Raises:
        VisionError: ``image`` is not an (H, W, 3) uint8 array, or ``depth`` does not
            match it.
    """
    s = settings or DetectorSettings()
    _check(image, depth)
    hsv = cast(_U8, cv2.cvtColor(cv2.GaussianBlur(image, (3, 3), 0), cv2.COLOR_BGR2HSV))
    ripe, unripe = _colour_masks(hsv, s)
    return detections_in_masks(ripe, unripe, camera, depth, s)


def detections_in_masks(
    ripe: npt.NDArray[np.uint8],
    unripe: npt.NDArray[np.uint8],
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None,
    s: DetectorSettings,
) -> list[BerryDetection]:
    """The berries of the ``ripe`` and ``unripe`` pixel masks, whatever made them (the
    colour thresholds, a pixel network): closed, split into fruit-shaped blobs, each
    placed and sized (the shape stage every detector shares)."""
    out = []
    for mask in (ripe, unripe):
        for blob in _blobs(_close(mask), s):
            det = _detection(blob, ripe, unripe, camera, depth, s)
            if det is not None:
                out.append(det)
    return out


def _check(image: object, depth: object) -> None:
    if not isinstance(image, np.ndarray):
        raise VisionError(f"image must be a numpy array, got {type(image).__name__}")
    if image.dtype != np.uint8:
        raise VisionError(f"image must be uint8 (BGR as OpenCV reads it), got {image.dtype}")
    if image.ndim != 3 or image.shape[2] != 3 or min(image.shape[:2]) == 0:
        raise VisionError(f"image must be (H, W, 3) BGR, got shape {image.shape}")
    if depth is not None:
        if not isinstance(depth, np.ndarray) or depth.shape != image.shape[:2]:
            shape = getattr(depth, "shape", None)
            raise VisionError(f"depth must be an (H, W) array like image, got shape {shape}")


def fruit_mask(
    image: npt.NDArray[np.uint8], settings: DetectorSettings | None = None
) -> npt.NDArray[np.uint8]:
    """The pixels (0/255) of either fruit colour class in a BGR image, closed over the
    drupelet gaps: the silhouettes that stereo matches (:mod:`softarm.perception.stereo`)."""
    s = settings or DetectorSettings()
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


def _blobs(mask: npt.NDArray[np.uint8], s: DetectorSettings) -> list[npt.NDArray[np.int32]]:
    """Outer contours of the compact blobs of ``mask``, holes filled."""
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    out = []
    for c in contours:
        area = cv2.contourArea(c)
        if area < s.min_area_px or len(c) < 5:
            continue
        hull = cv2.contourArea(cv2.convexHull(c))
        (_, _), (a, b), _ = cv2.fitEllipse(c)
        if hull <= 0 or area / hull < s.min_solidity:
            continue
        if max(a, b) > s.max_elongation * max(min(a, b), 1e-6):
            continue
        out.append(cast(npt.NDArray[np.int32], c))
    return out


def _detection(
    contour: npt.NDArray[np.int32],
    ripe: npt.NDArray[np.uint8],
    unripe: npt.NDArray[np.uint8],
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None,
    s: DetectorSettings,
) -> BerryDetection | None:
    mask = np.zeros(ripe.shape, np.uint8)
    cv2.drawContours(mask, [contour], -1, 255, thickness=cv2.FILLED)
    inside = mask > 0
    n_ripe = int(np.count_nonzero(ripe[inside]))
    n_unripe = int(np.count_nonzero(unripe[inside]))
    p_ripe = n_ripe / max(n_ripe + n_unripe, 1)
    m = cv2.moments(mask, binaryImage=True)
    cx, cy = m["m10"] / m["m00"], m["m01"] / m["m00"]
    radius = float(np.sqrt(m["m00"] / np.pi))
    position = None
    if depth is not None:
        position = _position(inside, (cx, cy), radius, camera, depth)
        if position is not None and not _fruit_sized(radius, position[2], camera, s):
            return None
    purity = (n_ripe + n_unripe) / m["m00"]
    solidity = m["m00"] / max(cv2.contourArea(cv2.convexHull(contour)), 1.0)
    ripeness: Ripeness = "ripe" if p_ripe >= 0.5 else "unripe"
    bx, by, bw, bh = cv2.boundingRect(contour)
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
    )


def _position(
    inside: npt.NDArray[np.bool_],
    center: tuple[float, float],
    radius_px: float,
    camera: CameraModel,
    depth: npt.NDArray[np.floating],
) -> FloatArray | None:
    """The berry's centre in the camera frame: the median depth of its visible surface,
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


def _fruit_sized(radius_px: float, z: float, camera: CameraModel, s: DetectorSettings) -> bool:
    diameter = 2.0 * radius_px * z / camera.focal
    return s.diameter_m[0] <= diameter <= s.diameter_m[1]
