"""How much of a berry a camera would see with nothing in front of it: the pixel area of
its full silhouette, from the geometry it was drawn with (an ellipsoid core and
spherical drupelets), so that a labelled berry's visible fraction is its visible pixels
over this area (:mod:`softarm.sim.render.dataset`).

Each geom is projected through the camera model, lens distortion included, as the
convex hull of points on its surface, and the hulls are filled on a canvas that reaches
beyond the image: a berry cut by the image border counts as partly hidden.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.vision.camera_model import CameraModel

__all__ = ["silhouette_area"]

_ELLIPSOID = 4  # mjtGeom.mjGEOM_ELLIPSOID (sphere is 2: one radius)
_SURFACE_POINTS = 48
#: The hulls are filled at this many sub-pixels a side, so the area is not biased by
#: the pixels a fill takes along every edge.
_SUPERSAMPLE = 4


def _unit_sphere(n: int) -> FloatArray:
    """``n`` directions spread evenly over the sphere (a Fibonacci lattice)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (3.0 - np.sqrt(5.0)) * k
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


_DIRECTIONS = _unit_sphere(_SURFACE_POINTS)


def _surface(model: Any, data: Any, geom: int) -> FloatArray:
    """Points on the surface of a sphere or ellipsoid geom, in the world (base) frame."""
    size = model.geom_size[geom]
    radii = size if model.geom_type[geom] == _ELLIPSOID else np.full(3, size[0])
    rotation = data.geom_xmat[geom].reshape(3, 3)
    result: FloatArray = data.geom_xpos[geom] + (_DIRECTIONS * radii) @ rotation.T
    return result


def silhouette_area(
    model: Any,
    data: Any,
    geoms: npt.NDArray[np.intp],
    T_base_camera: FloatArray,
    camera: CameraModel,
) -> float | None:
    """Pixels the ``geoms`` (one berry's) would cover in ``camera`` at ``T_base_camera``
    if nothing hid them and the image had no border; None when part of the berry lies
    behind the camera."""
    T_camera_base = np.linalg.inv(T_base_camera)
    hulls = []
    for g in geoms:
        points = _surface(model, data, int(g)) @ T_camera_base[:3, :3].T + T_camera_base[:3, 3]
        if np.any(points[:, 2] <= 1e-3):
            return None
        hulls.append(cv2.convexHull(camera.project(points).astype(np.float32)).reshape(-1, 2))
    everything = np.vstack(hulls)
    origin = np.floor(everything.min(axis=0)) - 1.0
    width, height = ((np.ceil(everything.max(axis=0) - origin) + 2.0) * _SUPERSAMPLE).astype(int)
    canvas = np.zeros((height, width), np.uint8)
    for hull in hulls:
        corners = np.round((hull - origin) * _SUPERSAMPLE).astype(np.int32)
        cv2.fillConvexPoly(canvas, corners, 1)
    return float(np.count_nonzero(canvas)) / _SUPERSAMPLE**2
