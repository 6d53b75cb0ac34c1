"""Random poses for vision experiments: a marker cube in front of an eye-to-hand camera and a
berry tag close to an eye-in-hand camera. Used by tests, benchmarks and examples."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from softarm.checks import FloatArray


def random_cube_pose(
    rng: np.random.Generator,
    distance: tuple[float, float] = (0.9, 1.1),
    lateral: float = 0.15,
    tilt_deg: float = 25.0,
) -> FloatArray:
    """``T_camera_cube`` for a cube hanging from the arm: cube +z roughly up (camera -y),
    random yaw about it, a random tilt up to ``tilt_deg``, ``distance`` (m) along the
    optical axis and up to ``lateral`` (m) sideways."""
    up = Rotation.from_matrix(np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]))  # cube z → -y_cam
    yaw = Rotation.from_rotvec([0, 0, rng.uniform(0, 2 * np.pi)])
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    tilt = Rotation.from_rotvec(axis * np.deg2rad(rng.uniform(0, tilt_deg)))
    pose = np.eye(4)
    pose[:3, :3] = (tilt * up * yaw).as_matrix()
    z = rng.uniform(*distance)
    pose[:3, 3] = [rng.uniform(-lateral, lateral), rng.uniform(-lateral, lateral) * 0.6, z]
    return pose


def random_facing_pose(
    rng: np.random.Generator, distance: tuple[float, float], max_angle_deg: float = 35.0
) -> FloatArray:
    """``T_camera_marker`` of a tag facing the camera (z towards it) within
    ``max_angle_deg`` of frontal, centred near the optical axis at ``distance`` (m)."""
    face = Rotation.from_rotvec([np.pi, 0, 0])  # marker z → -z_cam, marker y → -y_cam (up)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    tilt = Rotation.from_rotvec(axis * np.deg2rad(rng.uniform(0, max_angle_deg)))
    roll = Rotation.from_rotvec([0, 0, rng.uniform(-np.pi, np.pi)])
    pose = np.eye(4)
    pose[:3, :3] = (tilt * face * roll).as_matrix()
    z = rng.uniform(*distance)
    pose[:3, 3] = [rng.uniform(-0.1, 0.1) * z, rng.uniform(-0.1, 0.1) * z, z]
    return pose


def facing_pose(distance: float, x: float = 0.0, y: float = 0.0) -> FloatArray:
    """``T_camera_marker`` of a tag facing the camera squarely (marker z towards it, marker
    y up) at (x, y, distance) in the camera frame."""
    pose = np.diag([1.0, -1.0, -1.0, 1.0])
    pose[:3, 3] = [x, y, distance]
    return pose
