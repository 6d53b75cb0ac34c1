"""What C1 saw, drawn on its image: each mapped berry as a circle (ripe magenta, unripe
green) and each fitted cane as its curve, projected through the calibrated camera."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

from softarm.perception._inputs import bgr_image, instance
from softarm.perception.bush_map import BushMap
from softarm.vision.camera_model import CameraModel
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["draw_bush_map"]

RIPE, UNRIPE, CANE = (255, 0, 255), (0, 220, 0), (0, 200, 255)  # BGR
#: Only what lies at least this far (m) in front of the eye is drawn...
MIN_DEPTH = 0.01
#: ...and falls, through the pinhole, within this many image sizes beyond the image's
#: edges: a point far off the axis projects millions of pixels out (beyond OpenCV's
#: integer coordinates), or, through the distortion polynomial, back into the image.
MARGIN = 0.5


def draw_bush_map(
    image: npt.NDArray[np.uint8], bush_map: BushMap, stereo: StereoCamera
) -> npt.NDArray[np.uint8]:
    """A copy of C1's left ``image`` with ``bush_map``'s berries and canes on it; what
    lies behind the eye or far outside its view is left out.

    Raises:
        VisionError: ``image`` is not an (H, W, 3) uint8 BGR image.
        InputError: ``bush_map`` is not a BushMap or ``stereo`` not a StereoCamera.
    """
    out = bgr_image(image, "image").copy()
    instance(bush_map, BushMap, "bush_map")
    instance(stereo, StereoCamera, "stereo")
    T_left_base = invert(stereo.T_base_left)
    cam = stereo.left
    for cane in bush_map.canes:
        u = np.linspace(0.0, 1.0, 60)
        curve = (cane.coeffs @ np.vander(u, cane.coeffs.shape[1], increasing=True).T).T
        pts = _to_camera(curve, T_left_base)
        for run in _runs(_drawable(out.shape, pts, cam)):
            px = cam.project(pts[run])
            cv2.polylines(out, [np.round(px).astype(np.int32)], False, CANE, 2, cv2.LINE_AA)
    for berry in bush_map.berries:
        p = _to_camera(berry.position[None], T_left_base)
        if not _drawable(out.shape, p, cam)[0]:
            continue
        centre = cam.project(p)[0]
        radius = max(4, min(round(cam.focal * berry.radius / float(p[0, 2])), max(out.shape)))
        colour = RIPE if berry.ripeness == "ripe" else UNRIPE
        c = (round(centre[0]), round(centre[1]))
        cv2.circle(out, c, radius + 3, colour, 2, cv2.LINE_AA)
        cv2.putText(out, str(berry.id), (c[0] + radius + 4, c[1]), cv2.FONT_HERSHEY_SIMPLEX,
                    0.5, colour, 1, cv2.LINE_AA)  # fmt: skip
    return out


def _drawable(
    shape: tuple[int, ...], points: npt.NDArray[np.float64], cam: CameraModel
) -> npt.NDArray[np.bool_]:
    """Which camera-frame ``points`` (n, 3) are drawn: at least MIN_DEPTH in front of
    the eye, and within MARGIN image sizes of the image through the pinhole."""
    height, width = shape[:2]
    front = points[:, 2] >= MIN_DEPTH
    z = np.where(front, points[:, 2], 1.0)
    K = cam.matrix
    x = K[0, 0] * points[:, 0] / z + K[0, 1] * points[:, 1] / z + K[0, 2]
    y = K[1, 1] * points[:, 1] / z + K[1, 2]
    inside: npt.NDArray[np.bool_] = (
        front
        & (np.abs(x - width / 2) <= (0.5 + MARGIN) * width)
        & (np.abs(y - height / 2) <= (0.5 + MARGIN) * height)
    )
    return inside


def _runs(keep: npt.NDArray[np.bool_]) -> list[npt.NDArray[np.intp]]:
    """The index runs of at least two consecutive kept points (the pieces of a curve)."""
    idx = np.flatnonzero(keep)
    pieces = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if idx.size else []
    return [p for p in pieces if p.size >= 2]


def _to_camera(
    points: npt.NDArray[np.float64], T_camera_base: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    return points @ T_camera_base[:3, :3].T + T_camera_base[:3, 3]
