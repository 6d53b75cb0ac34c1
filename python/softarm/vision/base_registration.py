"""Online registration of a fixed camera to the robot base from the base ArUco tag
(section II-C): T_base_camera = T_base_tag · (T_camera_tag)⁻¹, averaged over frames.

This is the T_C1^Base of eq. (22). For an offline registration from surveyed point pairs
use :func:`~softarm.vision.registration.register_points` with points in the camera frame
as ``source`` and the same points in the base frame as ``target``.
"""

from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

from softarm.errors import ParameterError
from softarm.vision._checks import FloatArray, as_pose, positive
from softarm.vision.camera_model import CameraModel
from softarm.vision.detector import MarkerDetector, square_marker_poses
from softarm.vision.dictionaries import check_marker_id
from softarm.vision.poses import invert, rotation_angle


class BaseRegistration:
    """Estimates ``T_base_camera`` from the base tag ``tag_id`` (side ``tag_length``, m)
    mounted at ``T_base_tag`` on the base (identity: the tag frame is the base frame).

    The camera is assumed static: the estimate is the mean of the last ``window`` frames
    (positions averaged, rotations by the chordal mean of scipy's ``Rotation.mean``).
    """

    def __init__(
        self,
        camera: CameraModel,
        tag_id: int,
        tag_length: float,
        T_base_tag: npt.ArrayLike | None = None,
        dictionary: str = "DICT_4X4_50",
        window: int = 30,
    ) -> None:
        self.camera = camera
        self.tag_id = check_marker_id(dictionary, tag_id)
        self.tag_length = positive(tag_length, "tag_length")
        self.T_base_tag = np.eye(4) if T_base_tag is None else as_pose(T_base_tag, "T_base_tag")
        if int(window) < 1:
            raise ParameterError(f"window must be >= 1, got {window}")
        self.detector = MarkerDetector(dictionary)
        self._history: deque[FloatArray] = deque(maxlen=int(window))

    def observe(self, image: npt.NDArray[Any] | None) -> FloatArray | None:
        """``T_base_camera`` from this frame alone, or None if the tag is not seen."""
        for det in self.detector.detect(image, self.camera):
            if det.marker_id != self.tag_id:
                continue
            sols = square_marker_poses(det.corners, self.camera, self.tag_length)
            current = self.T_base_camera
            pick = sols[0]
            if current is not None and len(sols) > 1:
                # Planar ambiguity: keep the solution consistent with the running estimate.
                prior = invert(current) @ self.T_base_tag  # expected T_camera_tag
                pick = min(sols, key=lambda s: rotation_angle(s.T_camera_marker, prior))
            return self.T_base_tag @ invert(pick.T_camera_marker)
        return None

    def update(self, image: npt.NDArray[Any] | None) -> FloatArray | None:
        """Add this frame's observation (if any); return the averaged ``T_base_camera``."""
        obs = self.observe(image)
        if obs is not None:
            self._history.append(obs)
        return self.T_base_camera

    @property
    def T_base_camera(self) -> FloatArray | None:
        """The averaged camera pose in the base frame, or None before any observation."""
        if not self._history:
            return None
        poses = np.stack(list(self._history))
        out = np.eye(4)
        out[:3, :3] = Rotation.from_matrix(poses[:, :3, :3]).mean().as_matrix()
        out[:3, 3] = poses[:, :3, 3].mean(axis=0)
        return out

    def reset(self) -> None:
        """Drop all observations (after the camera has been moved)."""
        self._history.clear()
