"""Which pixels are canes, and their depth from C1's stereo pair.

A cane is a thin tube (5–8 mm, 3–8 px at 1 m for the ZED2) coloured olive to brown:
hue between the brown of bark and the yellow-green of a young cane, short of a leaf's
green; saturated (the backdrop and the soil are greyer); textured around it (a
flat backdrop, where stereo matching only guesses, is not); and thin: a band-pass on
width (a 3×3 opening removes the mixed pixels at leaf edges, an 11 px opening finds the
berries and other blobs, which are taken out).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.vision.stereo_camera import Rectification

__all__ = ["CaneLook", "cane_mask", "half_width_px", "matched_disparity", "stereo_disparity"]

BoolImage = npt.NDArray[np.bool_]


@dataclass(frozen=True)
class CaneLook:
    """Colour and shape thresholds (OpenCV HSV: hue 0–180, saturation and value 0–255;
    ``min_texture``: grey-level standard deviation over 7×7 pixels; widths in pixels)."""

    hue: tuple[int, int] = (10, 46)
    min_saturation: int = 105
    min_value: int = 25
    min_texture: float = 4.0
    thinnest: int = 3
    blob: int = 11


def cane_mask(bgr: npt.NDArray[np.uint8], look: CaneLook) -> BoolImage:
    """Pixels of ``bgr`` that look like a cane (see the module docstring)."""
    hsv = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)
    h, s, v = cv2.split(hsv)
    colour = (h >= look.hue[0]) & (h <= look.hue[1]) & (s >= look.min_saturation)
    colour &= v >= look.min_value
    grey = cast(npt.NDArray[np.uint8], cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY))
    colour &= _texture(grey) >= look.min_texture
    return _thin(colour.astype(np.uint8), look)


def _texture(grey: npt.NDArray[np.uint8]) -> npt.NDArray[np.float32]:
    """Local standard deviation of the grey level over 7×7 pixels."""
    g = grey.astype(np.float32)
    mean = cv2.boxFilter(g, -1, (7, 7))
    return np.sqrt(np.maximum(cv2.boxFilter(g * g, -1, (7, 7)) - mean * mean, 0.0))


def _thin(mask: npt.NDArray[np.uint8], look: CaneLook) -> BoolImage:
    """The parts of ``mask`` at least ``thinnest`` and less than ``blob`` pixels wide."""
    square = np.ones((look.thinnest, look.thinnest), np.uint8)
    kept = cv2.morphologyEx(mask, cv2.MORPH_OPEN, square)
    disk = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (look.blob, look.blob))
    blobs = cv2.morphologyEx(mask, cv2.MORPH_OPEN, disk)
    result: BoolImage = (kept > 0) & (blobs == 0)
    return result


def half_width_px(mask: BoolImage) -> npt.NDArray[np.float32]:
    """At each mask pixel, half the local width of the mask (pixels): the largest
    distance to the mask's edge within 5×5 pixels, less half a pixel."""
    distance = cv2.distanceTransform(mask.astype(np.uint8), cv2.DIST_L2, 3)
    widest = cv2.dilate(distance, np.ones((5, 5), np.uint8))
    return np.where(mask, np.maximum(widest - 0.5, 0.5), 0.0)


def stereo_disparity(
    left: npt.NDArray[np.uint8],
    right: npt.NDArray[np.uint8],
    rect: Rectification,
    mask: BoolImage,
    depth_range: tuple[float, float],
    smoothness: tuple[int, int] = (4, 16),
) -> npt.NDArray[np.float32]:
    """Disparity (pixels, NaN where unknown) of the rectified ``left`` from
    ``right`` (OpenCV's StereoSGBM, 3×3 blocks), computed only over the rows and
    columns that ``mask`` occupies, for depths within ``depth_range`` (m).

    ``smoothness``: SGBM's penalties P1, P2 for a disparity step of one pixel and of
    more. They are low: a cane is 3–8 pixels wide, and strong penalties (72, 288, the
    usual 8 and 32 per block pixel) carry the disparity of the leaf or backdrop around
    it into the cane along the aggregation paths (on tuning bushes 0–4 and 900–919,
    (72, 288) → (4, 16) took the cane map's coverage from 0.83 to 0.86, its
    precision from 0.87 to 0.91 and its median from 1.5 to 0.95 mm)."""
    fb = rect.focal * rect.baseline
    d_min = int(np.floor(fb / depth_range[1]))
    n_disp = 16 * int(np.ceil((fb / depth_range[0] - d_min) / 16))
    disparity = np.full(mask.shape, np.nan, np.float32)
    rows, cols = np.nonzero(mask)
    if rows.size == 0:
        return disparity
    pad = 4
    y0, y1 = max(rows.min() - pad, 0), min(rows.max() + pad + 1, mask.shape[0])
    x1 = min(cols.max() + pad + 1, mask.shape[1])
    # SGBM leaves the first minDisparity + numDisparities columns of its input
    # unmatched, so the crop reaches that far left of the mask; past the image's edge
    # it is padded with black, where a pixel whose match lies inside the right image
    # still finds it (a cane near the left edge).
    x0 = cols.min() - pad - d_min - n_disp
    p1, p2 = smoothness
    sgbm = cv2.StereoSGBM.create(
        minDisparity=d_min, numDisparities=n_disp, blockSize=3, P1=p1, P2=p2,
        uniquenessRatio=10, speckleWindowSize=100, speckleRange=2,
    )  # fmt: skip
    edge = max(-x0, 0)
    grey = [_padded_grey(img[y0:y1, x0 + edge : x1], edge) for img in (left, right)]
    raw = sgbm.compute(grey[0], grey[1]).astype(np.float32)[:, edge:] / 16.0
    raw[raw < d_min] = np.nan
    disparity[y0:y1, x0 + edge : x1] = raw
    return disparity


def matched_disparity(
    left: npt.NDArray[np.uint8],
    right: npt.NDArray[np.uint8],
    rect: Rectification,
    mask: BoolImage,
    depth_range: tuple[float, float],
    match_far: float | None,
    smoothness: tuple[int, int] = (4, 16),
    ties_in_range: bool = True,
) -> npt.NDArray[np.float32]:
    """Disparity (pixels, NaN where unknown) of ``mask``'s pixels as
    :func:`stereo_disparity` gives it, searched out to ``match_far`` (m) beyond
    ``depth_range``'s far end (None: the range alone), so that a cane beyond the range
    is matched at its own, smaller disparity (and dropped by whoever keeps the range)
    rather than aliased to a neighbour's disparity inside it.

    ``ties_in_range``: where the wider search leaves a pixel unmatched, it takes the
    disparity of the search within the range. SGBM leaves a pixel unmatched when a
    second disparity costs within its uniqueness ratio (10 %) of the best; where the
    search within the range found one unique among the range's own disparities, the
    rival lies beyond the range: a tie between a near match and a far one. The wider search
    drops a pixel only where its far match beats every match within the range by that
    margin. Without it, the wider search loses 6–8 % of the near canes' correctly
    matched pixels in the row (1.8 % in the bush; tuning renders 311000–311008), 92–96 %
    of them left unmatched by such a tie, 2–6 % matched beyond the range: a cane so
    thinned and thinned out can fail the fit's evidence. But a tie does not say which
    side is right: of the pixels the rule returns there, about as many lie beyond the
    range (30–48 % in the row) as are near canes' pixels matched right (28–35 %), and
    with it the far budget is less precise (docs/perception-candidates.md, "Ties between the range
    and beyond")."""
    if match_far is None or match_far <= depth_range[1]:
        return stereo_disparity(left, right, rect, mask, depth_range, smoothness)
    wide = stereo_disparity(left, right, rect, mask, (depth_range[0], match_far), smoothness)
    if not ties_in_range:
        return wide
    tied = np.isnan(wide) & mask
    if not tied.any():
        return wide
    near = stereo_disparity(left, right, rect, mask, depth_range, smoothness)
    return np.where(tied, near, wide).astype(np.float32)


def _padded_grey(bgr: npt.NDArray[np.uint8], left_pad: int) -> npt.NDArray[np.uint8]:
    """``bgr`` in grey with ``left_pad`` black columns before it."""
    grey = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    return cast(
        npt.NDArray[np.uint8],
        cv2.copyMakeBorder(grey, 0, 0, left_pad, 0, cv2.BORDER_CONSTANT, value=0),
    )
