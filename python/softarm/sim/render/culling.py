"""Frustum culling for the software rasteriser: the geoms that cannot reach a render's
pixels are left out of it.

MuJoCo hands every geom of the scene to OpenGL, and Mesa's software rasteriser
transforms and clips each one's triangles whether or not it lands in the picture. A C1
window around the cube or C2's narrow view sees a fraction of the bush's 400-odd geoms,
so most of that work is wasted. A geom is left out when its bounding sphere
(``geom_rbound`` about its centre) lies wholly outside one of the frustum's side planes
or wholly behind the camera: it then covers no pixel, so the image is the same, pixel
for pixel (the tests compare them).

MuJoCo's camera frame: x right, y up, looking along -z; a pixel (u, v) of a pinhole of
focal length f (px) and principal point (cx, cy) sees the ray (u - cx, -(v - cy), -f).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray

__all__ = ["MARGIN_PX", "in_frustum"]

#: Pixels added on every side of the picture before culling, so that a sphere grazing
#: the border (and the rasteriser's half-pixel rules) is always drawn.
MARGIN_PX = 2.0


def in_frustum(
    centres: FloatArray,
    radii: FloatArray,
    size: tuple[int, int],
    focal: float,
    principal: tuple[float, float],
) -> npt.NDArray[np.bool_]:
    """Which spheres (``centres`` (N, 3) in MuJoCo's camera frame, ``radii`` (N,)) may
    show in the ``size`` = (w, h) picture of a pinhole with ``focal`` (px) and
    ``principal`` (cx, cy) px. Conservative: a sphere that is kept may still cover no
    pixel, one that is left out covers none. A radius of 0 or less (MuJoCo's planes,
    unbounded) is always kept."""
    x, y, depth = centres[:, 0], -centres[:, 1], -centres[:, 2]
    r = radii
    w, h = size
    keep = depth > -r
    # Each side plane passes through the camera centre; its inward normal is
    # (±1, 0, ∓a) / sqrt(1 + a²) in (x, y-down, depth) for the bound x = a·depth.
    bounds = (
        (x, (-0.5 - MARGIN_PX - principal[0]) / focal, 1.0),
        (x, (w - 0.5 + MARGIN_PX - principal[0]) / focal, -1.0),
        (y, (-0.5 - MARGIN_PX - principal[1]) / focal, 1.0),
        (y, (h - 0.5 + MARGIN_PX - principal[1]) / focal, -1.0),
    )
    for coord, a, side in bounds:
        keep &= side * (coord - a * depth) / np.sqrt(1.0 + a * a) > -r
    result: npt.NDArray[np.bool_] = keep | (radii <= 0.0)
    return result
