"""A berry's image centre from both eyes of C1's rectified pair, and the point its ray
starts from.

C1's ray to a berry (:class:`~softarm.perception.approach.RayCrossing`) fixes the
berry across C1's line of sight; the crossing with C2's ray turns an error of it into
a larger one along the approach (docs/harvest.md, "Where the fine error comes from").
Each eye's centre is off by a few tenths of a pixel (the drupelets on the outline,
the background behind the edge), and the two eyes' errors are barely correlated: the
mean of the two centres is the better direction. Seen from the middle of the
baseline, a point at depth z = f B / d lies in the direction of the mean of its left
and right image positions, whatever the disparity d: so C1's ray starts at the
baseline's middle (:func:`ray_origin`) and the berry is triangulated at
:func:`mean_centre`, which puts it on that ray. A disparity error then moves the
berry along C1's ray only, as it did along the left eye's.
"""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.perception.berries import MAX_REFINED_RADIUS, BerryDetection
from softarm.perception.berry_centre import RING, silhouette_centre
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["AGREE_PX", "mean_centre", "ray_origin"]

#: The right eye's centre, carried into the left image by the disparity, must lie this
#: close (px) to the left one, and its silhouette's area within AREA_RATIO of the left
#: one's: else the fruit is partly hidden in one eye, or another fruit touches it there.
AGREE_PX = 1.0
AREA_RATIO = (0.8, 1.25)
#: The right silhouette is looked for within this many pixels of the left one shifted
#: by the disparity.
SEARCH_PX = 2


def ray_origin(stereo: StereoCamera) -> FloatArray:
    """The middle of C1's baseline in the base frame: where C1's rays to the berries
    that :func:`~softarm.perception.stereo.locate_berries` places start."""
    middle = np.append(0.5 * stereo.T_left_right[:3, 3], 1.0)
    out: FloatArray = (stereo.T_base_left @ middle)[:3]
    return out


def mean_centre(
    det: BerryDetection,
    disparity: float,
    right_colour: npt.NDArray[np.uint8],
    right_fruit: npt.NDArray[np.uint8],
) -> tuple[float, float]:
    """The rectified left pixel to triangulate ``det`` at with ``disparity``: the mean
    of its left centre and its right centre carried into the left image by the
    disparity (the berry's direction from the baseline's middle is then the mean of
    the two eyes'). The left centre alone where the right one cannot be measured as
    well (a fruit whose left centre was not refined, near the image's edge, or whose
    right silhouette does not match its left one: see :data:`AGREE_PX`).

    ``right_colour`` is the rectified right image blurred as the detector blurs the
    left one, ``right_fruit`` its fruit mask (0/255), both of the left image's size.
    """
    left = (float(det.center[0]), float(det.center[1]))
    if det.ripeness != "ripe" or det.radius > MAX_REFINED_RADIUS:
        return left  # the detector refines only these centres (berries.MAX_REFINED_RADIUS)
    shift = round(disparity)
    x, y, w, h = det.box
    pad = RING[1] + 1 + SEARCH_PX
    x0, y0, x1, y1 = x - pad, y - pad, x + w + pad, y + h + pad
    height, width = right_fruit.shape
    if x0 - shift < 0 or y0 < 0 or x1 > width or y1 > height:
        return left
    own = det.mask_window(x0, y0, x1, y1).astype(np.uint8)
    near = cv2.dilate(own, np.ones((2 * SEARCH_PX + 1,) * 2, np.uint8)) > 0
    window = slice(y0, y1), slice(x0 - shift, x1 - shift)
    mask = (right_fruit[window] > 0) & near
    area, own_area = int(mask.sum()), int(own.sum())
    if own_area == 0 or not AREA_RATIO[0] <= area / own_area <= AREA_RATIO[1]:
        return left
    ys, xs = np.nonzero(mask)
    centroid = (float(xs.mean()) + x0 - shift, float(ys.mean()) + y0)
    xr, yr = silhouette_centre(mask, right_colour[window], (x0 - shift, y0), centroid)
    carried = (xr + disparity, yr)
    if np.hypot(carried[0] - left[0], carried[1] - left[1]) > AGREE_PX:
        return left
    return 0.5 * (left[0] + carried[0]), 0.5 * (left[1] + carried[1])
