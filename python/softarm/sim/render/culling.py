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

__all__ = ["MARGIN_PX", "in_frustum", "swept_in_frustum"]

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
    keep = np.ones(len(radii), bool)
    for distance in _plane_distances(centres, size, focal, principal):
        keep &= distance > -radii
    result: npt.NDArray[np.bool_] = keep | (radii <= 0.0)
    return result


def swept_in_frustum(
    starts: FloatArray,
    ends: FloatArray,
    radii: FloatArray,
    size: tuple[int, int],
    focal: float,
    principal: tuple[float, float],
) -> npt.NDArray[np.bool_]:
    """Which spheres of ``radii`` (N,) swept from ``starts`` to ``ends`` (N, 3, MuJoCo's
    camera frame) may reach the picture of :func:`in_frustum`. A point's distance to a
    plane is linear along the sweep, so the sweep lies wholly outside a plane exactly
    when both its ends do; conservative as :func:`in_frustum` (a sweep passing a corner
    of the frustum may be kept)."""
    keep = np.ones(len(radii), bool)
    planes = zip(
        _plane_distances(starts, size, focal, principal),
        _plane_distances(ends, size, focal, principal),
        strict=True,
    )
    for a, b in planes:
        keep &= np.maximum(a, b) > -radii
    return keep


def _plane_distances(
    points: FloatArray, size: tuple[int, int], focal: float, principal: tuple[float, float]
) -> list[FloatArray]:
    """Each of ``points``' (N, 3, camera frame) signed distances (m, inside positive)
    to the picture's frustum's planes: the camera's own (depth), then its four sides."""
    x, y, depth = points[:, 0], -points[:, 1], -points[:, 2]
    w, h = size
    # Each side plane passes through the camera centre; its inward normal is
    # (±1, 0, ∓a) / sqrt(1 + a²) in (x, y-down, depth) for the bound x = a·depth.
    bounds = (
        (x, (-0.5 - MARGIN_PX - principal[0]) / focal, 1.0),
        (x, (w - 0.5 + MARGIN_PX - principal[0]) / focal, -1.0),
        (y, (-0.5 - MARGIN_PX - principal[1]) / focal, 1.0),
        (y, (h - 0.5 + MARGIN_PX - principal[1]) / focal, -1.0),
    )
    return [depth] + [side * (c - a * depth) / np.sqrt(1.0 + a * a) for c, a, side in bounds]
