"""Plain OpenCV baseline for a marker cube: default ``ArucoDetector`` parameters, the cube's
``Board`` with ``matchImagePoints`` and one ``solvePnP`` (``SOLVEPNP_ITERATIVE``), no
refinement or disambiguation. Kept for benchmarks and accuracy comparisons."""

from __future__ import annotations

from typing import Any

import cv2
import numpy.typing as npt

from softarm.vision._checks import FloatArray, as_gray
from softarm.vision.camera_model import CameraModel
from softarm.vision.cube import MarkerCube
from softarm.vision.dictionaries import get_dictionary
from softarm.vision.poses import pose_from_rvec_tvec


class OpenCVBaseline:
    """``estimate_pose(image, camera)`` of ``cube`` the way the OpenCV tutorials do it."""

    def __init__(self, cube: MarkerCube) -> None:
        self.cube = cube
        self._detector = cv2.aruco.ArucoDetector(
            get_dictionary(cube.dictionary), cv2.aruco.DetectorParameters()
        )

    def estimate_pose(self, image: npt.NDArray[Any], camera: CameraModel) -> FloatArray | None:
        """``T_camera_cube`` or None."""
        corners, ids, _ = self._detector.detectMarkers(as_gray(image))
        if ids is None or len(ids) == 0:
            return None
        obj, img = self.cube.board.matchImagePoints(corners, ids)
        if obj is None or len(obj) < 4:
            return None
        ok, rvec, tvec = cv2.solvePnP(
            obj, img, camera.matrix, camera.distortion, flags=cv2.SOLVEPNP_ITERATIVE
        )
        return pose_from_rvec_tvec(rvec, tvec) if ok else None
