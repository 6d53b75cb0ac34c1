"""What C1 saw, drawn on its image: each mapped berry as a circle (ripe magenta, unripe
green) and each fitted cane as its curve, projected through the calibrated camera."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

from softarm.perception.bush_map import BushMap
from softarm.perception.stereo_camera import StereoCamera
from softarm.vision.poses import invert

__all__ = ["draw_bush_map"]

RIPE, UNRIPE, CANE = (255, 0, 255), (0, 220, 0), (0, 200, 255)  # BGR


def draw_bush_map(
    image: npt.NDArray[np.uint8], bush_map: BushMap, stereo: StereoCamera
) -> npt.NDArray[np.uint8]:
    """A copy of C1's left ``image`` with ``bush_map``'s berries and canes on it."""
    out = image.copy()
    T_left_base = invert(stereo.T_base_left)
    cam = stereo.left
    for cane in bush_map.canes:
        u = np.linspace(0.0, 1.0, 60)
        pts = (cane.coeffs @ np.vander(u, cane.coeffs.shape[1], increasing=True).T).T
        px = cam.project(_to_camera(pts, T_left_base))
        cv2.polylines(out, [np.round(px).astype(np.int32)], False, CANE, 2, cv2.LINE_AA)
    for berry in bush_map.berries:
        p = _to_camera(berry.position[None], T_left_base)
        centre = cam.project(p)[0]
        radius = max(4, round(cam.focal * berry.radius / float(p[0, 2])))
        colour = RIPE if berry.ripeness == "ripe" else UNRIPE
        c = (round(centre[0]), round(centre[1]))
        cv2.circle(out, c, radius + 3, colour, 2, cv2.LINE_AA)
        cv2.putText(out, str(berry.id), (c[0] + radius + 4, c[1]), cv2.FONT_HERSHEY_SIMPLEX,
                    0.5, colour, 1, cv2.LINE_AA)  # fmt: skip
    return out


def _to_camera(
    points: npt.NDArray[np.float64], T_camera_base: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    return points @ T_camera_base[:3, :3].T + T_camera_base[:3, 3]
