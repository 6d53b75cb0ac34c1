"""A window of a camera's pinhole image drawn alone, and the geoms' bounding spheres the
culling of a render goes by: what :class:`~softarm.sim.render.renderer.BushRenderer`
and :mod:`softarm.sim.render.window_composite` share."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.sim.render.mjcf import CameraSpec

__all__ = ["PIXEL", "geom_bounds", "window_camera"]

#: The sensor pixel pitch (m) the scene's cameras are declared with (mjcf._camera).
PIXEL = 1e-6


@contextmanager
def window_camera(
    mj: Any, model: Any, data: Any, spec: CameraSpec, origin: tuple[int, int], side: int
) -> Iterator[tuple[CameraSpec, tuple[float, float]]]:
    """Within the block, camera ``spec`` of the MuJoCo ``model`` draws the ``side``-pixel
    square of its pinhole image whose top-left pixel is ``origin`` (x0, y0), which may
    reach past the frame: its principal point is moved, so that only the window's pixels
    are drawn (a software rasteriser's cost goes with them), each the whole frame's.
    The camera's pose is placed in ``data`` (``mj_camlight``). Yields the window's
    camera spec and its principal point (px) in the window; the camera is restored
    after."""
    m = model
    cam = mj.mj_name2id(m, mj.mjtObj.mjOBJ_CAMERA, spec.name)
    saved = (m.cam_resolution[cam].copy(), m.cam_sensorsize[cam].copy(),
             m.cam_intrinsic[cam].copy())  # fmt: skip
    centre = (side - 1) / 2
    # MuJoCo takes the principal point as an offset of the image centre from it.
    px = centre - (spec.principal[0] - origin[0])
    py = centre - (spec.principal[1] - origin[1])
    m.cam_resolution[cam] = (side, side)
    m.cam_sensorsize[cam] = (side * PIXEL, side * PIXEL)
    m.cam_intrinsic[cam] = (spec.focal * PIXEL, spec.focal * PIXEL, px * PIXEL, py * PIXEL)
    try:
        mj.mj_kinematics(m, data)
        mj.mj_camlight(m, data)
        window = CameraSpec(spec.name, spec.T_parent_camera, (side, side), spec.focal, (0, 0))
        yield window, (spec.principal[0] - origin[0], spec.principal[1] - origin[1])
    finally:
        m.cam_resolution[cam], m.cam_sensorsize[cam], m.cam_intrinsic[cam] = saved


def geom_bounds(model: Any, arm: npt.NDArray[np.intp]) -> FloatArray:
    """Every geom's bounding radius (m) about its centre: MuJoCo's, but for the
    ``arm``'s geoms, which change size as it bends (MuJoCo's radius is the built
    size's), the larger of it and the sum of their sizes (a capsule's radius and
    half-length, a box's half-sides: a sphere about the centre holding the geom)."""
    radii: FloatArray = model.geom_rbound.copy()
    radii[arm] = np.maximum(radii[arm], model.geom_size[arm].sum(axis=1))
    return radii
