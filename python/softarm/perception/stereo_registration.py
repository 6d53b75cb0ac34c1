"""C1 placed on the base tag with both eyes of its stereo pair.

One eye gives a small tag's position well and its tilt poorly. Seen nearly face-on, an
8 cm tag at 0.77 m tilted by 0.7° moves its corners by about 0.03 px, the size of the
corner noise of a rendered or real image; that 0.7° of C1's registration moves the bush,
0.4 m from the tag, by 4–5 mm in the base frame (measured on rendered bushes 0–2 and 900:
0.70–0.79° and 4.1–5.1 mm from the left eye alone). The right eye, a baseline away, sees
the same tilt as about 0.09 px of disparity across the tag. The pose that minimises the
reprojection error of the tag's four corners in both eyes at once, the pair's
calibration held fixed (a two-view PnP, solved by Levenberg–Marquardt from the left eye's
IPPE solution), has the tilt ten times better (0.07–0.08° on the same bushes, the bush
moved by 0.5–0.6 mm).
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares

from softarm.checks import FloatArray
from softarm.errors import VisionError
from softarm.perception.stereo_camera import StereoCamera
from softarm.vision.base_registration import BaseRegistration
from softarm.vision.camera_model import CameraModel
from softarm.vision.detector import marker_object_points, square_marker_poses
from softarm.vision.poses import invert, pose_from_rvec_tvec, rvec_tvec_from_pose

__all__ = ["register_c1_stereo", "stereo_marker_pose"]

Pair = tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]


def stereo_marker_pose(
    left_corners: npt.ArrayLike,
    right_corners: npt.ArrayLike,
    stereo: StereoCamera,
    marker_length: float,
) -> FloatArray:
    """``T_left_marker`` (4, 4) of a square marker from its (4, 2) corners in each eye
    (distorted pixels, detection order): the left eye's IPPE poses refined to the least
    reprojection error over the eight corners of both eyes, the best one kept.

    Raises:
        VisionError: corners that are not a marker's, or no pose from the left eye.
    """
    solutions = square_marker_poses(left_corners, stereo.left, marker_length)
    if not solutions:
        raise VisionError("no pose of the marker from the left eye's corners")
    corners = [np.asarray(c, dtype=np.float64).reshape(4, 2) for c in (left_corners, right_corners)]
    obj = marker_object_points(marker_length).reshape(4, 3)
    T_right_left = invert(stereo.T_left_right)

    def residuals(x: FloatArray) -> FloatArray:
        T = pose_from_rvec_tvec(x[:3], x[3:])
        return np.concatenate(
            [
                _reprojection(stereo.left, T, obj, corners[0]),
                _reprojection(stereo.right, T_right_left @ T, obj, corners[1]),
            ]
        )

    # Both IPPE solutions start a refinement (the right eye settles the planar
    # ambiguity one eye leaves); the one with the least error over both eyes is kept.
    fits = [
        least_squares(
            residuals, np.concatenate(rvec_tvec_from_pose(s.T_camera_marker)).ravel(), method="lm"
        )
        for s in solutions
    ]
    best = min(fits, key=lambda f: float(f.cost))
    return pose_from_rvec_tvec(best.x[:3], best.x[3:])


def _reprojection(
    camera: CameraModel, T: FloatArray, obj: FloatArray, seen: FloatArray
) -> FloatArray:
    rvec, tvec = rvec_tvec_from_pose(T)
    projected, _ = cv2.projectPoints(obj, rvec, tvec, camera.matrix, camera.distortion)
    result: FloatArray = (projected.reshape(-1, 2) - seen).ravel()
    return result


def register_c1_stereo(
    pair: Callable[[], Pair],
    stereo: StereoCamera,
    tag_id: int,
    tag_length: float,
    T_base_tag: FloatArray,
    frames: int = 5,
    dictionary: str = "DICT_4X4_50",
) -> FloatArray:
    """``T_base_left`` from ``frames`` stereo pairs of the base tag (section II-C, eq. 22,
    with both eyes): a frame where only the left eye sees the tag gives that eye's pose,
    and the frames' poses are averaged as :class:`BaseRegistration` does.

    Args:
        pair: returns C1's (left, right) BGR images, distorted as read.
        stereo: the calibrated pair (its ``T_base_left`` is not used).
        tag_id, tag_length, T_base_tag, dictionary: the base tag.

    Raises:
        VisionError: the left eye never saw the tag.
    """
    reg = BaseRegistration(stereo.left, tag_id, tag_length, T_base_tag, dictionary, frames)
    for _ in range(frames):
        left, right = pair()
        corners = [
            _tag_corners(reg, image, camera)
            for image, camera in ((left, stereo.left), (right, stereo.right))
        ]
        if corners[0] is None:
            continue
        if corners[1] is None:
            reg.update(left)
            continue
        T_left_tag = stereo_marker_pose(corners[0], corners[1], stereo, tag_length)
        reg.add(reg.T_base_tag @ invert(T_left_tag))
    if reg.T_base_camera is None:
        raise VisionError(f"C1's left eye does not see base tag {tag_id}")
    return reg.T_base_camera


def _tag_corners(
    reg: BaseRegistration, image: npt.NDArray[np.uint8], camera: CameraModel
) -> FloatArray | None:
    for det in reg.detector.detect(image, camera):
        if det.marker_id == reg.tag_id:
            return np.asarray(det.corners, dtype=np.float64)
    return None
