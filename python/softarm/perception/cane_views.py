"""Cane points from two views of one camera at known poses: C2 on the arm, moved
sideways between them (the survey, :mod:`softarm.harvest.control.survey`), is a stereo pair
whose baseline is the move. It sees the bush from nearer and from another side than C1
does, so it fills in the canes C1's stereo leaves without depth: those hidden from
C1's right eye, and those behind the leaves C1 looks through.

The pair is rectified from the two poses (:class:`~softarm.vision.stereo_camera.
StereoCamera` with the second view as the right eye), and the cane pixels of the first
view (from the same source as C1's, :mod:`softarm.perception.cane_source`) are matched
and lifted to the centre line as C1's are (:func:`softarm.perception.canes.cane_points`):
the points beyond the settings' ``reach`` of the base dropped before the budget.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import VisionError
from softarm.perception.cane_pixels import half_width_px, stereo_disparity
from softarm.perception.cane_source import source_mask
from softarm.perception.canes import CaneSettings, centre_line_points
from softarm.vision.camera_model import CameraModel
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import Rectification, StereoCamera

__all__ = ["VIEW_DEPTHS", "pixel_size", "view_pair_points"]

#: Nearest and farthest depth (m) a cane is looked for at from the arm.
VIEW_DEPTHS = (0.1, 0.9)
#: Largest difference (px) between a pixel's disparity matched from the first view and
#: from the second.
LR_TOL = 1.0


def view_pair_points(
    first: npt.NDArray[np.uint8],
    second: npt.NDArray[np.uint8],
    camera: CameraModel,
    T_base_first: FloatArray,
    T_base_second: FloatArray,
    settings: CaneSettings | None = None,
    footprint: float | None = None,
) -> FloatArray:
    """(n, 4) rows as :func:`softarm.perception.canes.cane_points` gives them: a point on
    a cane's centre line (base frame, m) and the radius there, from ``camera``'s BGR
    images ``first`` and ``second`` taken at ``T_base_first`` and ``T_base_second``.

    The move between them must be mostly along the camera's x axis (the rows of the
    rectified pair); either way along it. ``footprint``: the size (m) of a pixel of
    the view these points join (C1's: its distance over its focal length); the points
    are thinned to as many per length of cane as that view gives, so that a cane's
    support (:class:`~softarm.perception.cane_curves.CurveSearch`) means the same
    length whichever camera saw it.

    Raises:
        VisionError: images that are not ``camera``'s BGR uint8 frames, a camera
            without an image size, or a move mostly along the camera's y or z axis.
    """
    settings = settings or CaneSettings()
    _check_views(first, second, camera)
    move = (invert(np.asarray(T_base_first, np.float64)) @ T_base_second)[:3, 3]
    if abs(move[0]) <= max(abs(move[1]), abs(move[2])):
        raise VisionError(
            f"the move between the views must be mostly along the camera's x axis, got {move}"
        )
    if move[0] < 0:  # the second view is the left eye
        first, second = second, first
        T_base_first, T_base_second = T_base_second, T_base_first
    pair = StereoCamera(camera, camera, T_base_first, invert(T_base_first) @ T_base_second)
    rect = pair.rectification
    left, right = rect.rectify(first, second)
    mask = source_mask(left, settings.look, settings.source)
    disparity = stereo_disparity(left, right, rect, mask, VIEW_DEPTHS, settings.smoothness)
    mask &= _consistent(left, right, rect, disparity, settings)
    rows, cols = np.nonzero(mask)
    surface = rect.triangulate(
        np.column_stack([cols, rows]).astype(np.float64), disparity[rows, cols]
    )
    radius = half_width_px(mask)[rows, cols] * surface[:, 2] / rect.focal
    if footprint is not None and len(surface):
        own = float(np.median(surface[:, 2])) / rect.focal
        step = max(1, round((footprint / own) ** 2))
        surface, radius = surface[::step], radius[::step]
    return centre_line_points(
        surface, radius, T_base_first, VIEW_DEPTHS, settings.max_points, settings.reach
    )


def pixel_size(stereo: StereoCamera, point: FloatArray) -> float:
    """The size (m) of one of ``stereo``'s rectified pixels at ``point`` (base frame):
    its distance from the left eye over the focal length; the ``footprint`` of
    :func:`view_pair_points` for points that join that camera's."""
    distance = float(np.linalg.norm(np.asarray(point) - stereo.T_base_left[:3, 3]))
    return distance / stereo.rectification.focal


def _consistent(
    left: npt.NDArray[np.uint8], right: npt.NDArray[np.uint8], rect: Rectification,
    disparity: npt.NDArray[np.float32], settings: CaneSettings,
) -> npt.NDArray[np.bool_]:  # fmt: skip
    """Pixels of ``left`` whose ``disparity`` the match the other way (``right``'s
    pixel against ``left``, found by mirroring both) agrees with within LR_TOL: where
    the two ways disagree, neither is more than a guess."""
    rows, cols = np.nonzero(np.isfinite(disparity))
    partner = np.round(cols - disparity[rows, cols]).astype(np.intp)
    inside = partner >= 0
    rows, cols, partner = rows[inside], cols[inside], partner[inside]
    wanted = np.zeros(disparity.shape, bool)
    wanted[rows, partner] = True
    width = disparity.shape[1]
    mirrored = [np.ascontiguousarray(img[:, ::-1]) for img in (right, left)]
    back = stereo_disparity(
        mirrored[0], mirrored[1], rect, wanted[:, ::-1], VIEW_DEPTHS, settings.smoothness
    )
    agree = np.abs(back[rows, width - 1 - partner] - disparity[rows, cols]) <= LR_TOL
    ok = np.zeros(disparity.shape, bool)
    ok[rows[agree], cols[agree]] = True
    return ok


def _check_views(first: object, second: object, camera: CameraModel) -> None:
    if camera.image_size is None:
        raise VisionError("camera needs its image_size")
    w, h = camera.image_size
    for name, image in (("first", first), ("second", second)):
        if not isinstance(image, np.ndarray) or image.dtype != np.uint8 or image.shape != (h, w, 3):
            got = (
                f"{image.dtype} array of shape {image.shape}"
                if isinstance(image, np.ndarray)
                else type(image).__name__
            )
            raise VisionError(f"{name} must be a ({h}, {w}, 3) uint8 BGR image, got {got}")
