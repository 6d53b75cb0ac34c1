"""Plain OpenCV baselines for a marker cube: ``ArucoDetector`` with OpenCV's default
parameters except the corner refinement, the cube's ``Board`` with ``matchImagePoints`` and
one ``solvePnP`` (``SOLVEPNP_ITERATIVE``), no edge refinement or disambiguation. Kept for
benchmarks and accuracy comparisons.

``refinement`` picks OpenCV's own corner refinement, so that the comparison is with
OpenCV at its best and not only its defaults:

- ``"none"``: ``CORNER_REFINE_NONE``, the default (corners of the fitted contour polygon);
- ``"subpix"``: ``CORNER_REFINE_SUBPIX`` (``cornerSubPix`` on each corner);
- ``"apriltag"``: ``CORNER_REFINE_APRILTAG`` (AprilTag 2's quad fitting on the edges).
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy.typing as npt

from softarm.errors import ParameterError
from softarm.vision._checks import FloatArray, as_gray
from softarm.vision.camera_model import CameraModel
from softarm.vision.cube import MarkerCube
from softarm.vision.dictionaries import get_dictionary
from softarm.vision.poses import pose_from_rvec_tvec

#: ``refinement`` names and OpenCV's corner refinement methods.
REFINEMENTS = {
    "none": cv2.aruco.CORNER_REFINE_NONE,
    "subpix": cv2.aruco.CORNER_REFINE_SUBPIX,
    "apriltag": cv2.aruco.CORNER_REFINE_APRILTAG,
}


class OpenCVBaseline:
    """``estimate_pose(image, camera)`` of ``cube`` the way the OpenCV tutorials do it, with
    ``refinement`` one of :data:`REFINEMENTS` (default ``"none"``, OpenCV's default)."""

    def __init__(self, cube: MarkerCube, refinement: str = "none") -> None:
        if refinement not in REFINEMENTS:
            raise ParameterError(
                f"refinement must be one of {sorted(REFINEMENTS)}, got {refinement!r}"
            )
        self.cube = cube
        self.refinement = refinement
        params = cv2.aruco.DetectorParameters()
        params.cornerRefinementMethod = REFINEMENTS[refinement]
        self._detector = cv2.aruco.ArucoDetector(get_dictionary(cube.dictionary), params)

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
