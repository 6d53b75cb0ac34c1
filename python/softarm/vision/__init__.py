"""Vision: ArUco tracking (OpenCV 5), the end-effector marker cube, registration, pose
filtering and two-camera fusion (paper sections II-C and III-D, eq. 21–22)."""

from softarm.vision.base_registration import BaseRegistration
from softarm.vision.baseline import OpenCVBaseline
from softarm.vision.calibration import calibrate_charuco, calibrate_chessboard
from softarm.vision.calibration_checks import CalibrationNotConverged
from softarm.vision.camera_model import CameraModel
from softarm.vision.crop import ImageCrop
from softarm.vision.cube import CubePose, CubeTracker, MarkerCube
from softarm.vision.detector import (
    Detection,
    MarkerDetector,
    MarkerPose,
    estimate_marker_poses,
    marker_object_points,
    square_marker_poses,
)
from softarm.vision.dictionaries import get_dictionary
from softarm.vision.filter import PoseLowPassFilter
from softarm.vision.fusion import CameraFusion, FusionEstimate
from softarm.vision.registration import RegistrationResult, register_points
from softarm.vision.stereo_camera import Rectification, StereoCamera
from softarm.vision.two_cameras import CameraVision, register_c1

__all__ = [
    "BaseRegistration",
    "CalibrationNotConverged",
    "CameraFusion",
    "CameraModel",
    "CameraVision",
    "CubePose",
    "CubeTracker",
    "Detection",
    "FusionEstimate",
    "ImageCrop",
    "MarkerCube",
    "MarkerDetector",
    "MarkerPose",
    "OpenCVBaseline",
    "PoseLowPassFilter",
    "Rectification",
    "RegistrationResult",
    "StereoCamera",
    "calibrate_charuco",
    "calibrate_chessboard",
    "estimate_marker_poses",
    "get_dictionary",
    "marker_object_points",
    "register_c1",
    "register_points",
    "square_marker_poses",
]
