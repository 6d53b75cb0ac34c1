"""Calibration of the arm model from measured end-effector poses (marker data).

``calibrate(nominal_arm, commands, poses)`` fits per-section radius, rest length, plate
offset and twist and per-actuator gains by weighted least squares on the core kinematics
(eq. 1-6, analytic Jacobian); the result, a :class:`Calibration`, predicts poses, reports
its residuals and is saved as ``model.toml``. ``excitation_set`` and ``collect`` drive a
plant (simulated or real) through a safe set of commands and measure the poses.
"""

from softarm.calibration.fit import calibrate
from softarm.calibration.metrics import PoseErrorStats, pose_errors
from softarm.calibration.result import Calibration, load_calibration, load_model

__all__ = [
    "Calibration",
    "PoseErrorStats",
    "calibrate",
    "load_calibration",
    "load_model",
    "pose_errors",
]
