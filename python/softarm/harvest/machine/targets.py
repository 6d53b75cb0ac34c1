"""Target poses and errors of the harvesting approach.

The gripper approaches every berry along ``approach`` (the bush lies along +Y of the base
frame, section IV-F). Only the direction of the gripper's z axis is prescribed: its roll
about that axis is free, so the target rotation is the smallest rotation that turns the
current z axis onto ``approach``, applied to the current orientation. The full orientation
error of the resolver (rotation vector of R_target · R_currentᵀ, docs/architecture.md) is
then exactly the pointing error.
"""

from __future__ import annotations

import numpy as np

from softarm import so3
from softarm.checks import FloatArray

__all__ = ["align_z", "approach_pose", "grasp_point", "pointing_error", "tool_pose"]


def align_z(rotation: FloatArray, axis: FloatArray) -> FloatArray:
    """``rotation`` (3, 3) turned by the smallest rotation taking its z column onto the
    unit vector ``axis`` (:func:`softarm.so3.rotation_between`)."""
    turn = so3.rotation_between(rotation[:, 2], axis)
    if turn is None:
        # Antiparallel: turn by pi about the current x axis.
        turn = so3.exp(np.pi * rotation[:, 0])
    return turn @ rotation


def approach_pose(
    current: FloatArray, berry: FloatArray, approach: FloatArray, distance: float
) -> FloatArray:
    """Target ``T_base_ee`` (4, 4): z along ``approach``, origin ``distance`` (m) short of
    ``berry`` along it; roll kept from ``current``."""
    target = np.eye(4)
    target[:3, :3] = align_z(current[:3, :3], approach)
    target[:3, 3] = berry - distance * approach
    return target


def tool_pose(
    current: FloatArray, point: FloatArray, approach: FloatArray, offset: float
) -> FloatArray:
    """Target ``T_base_ee`` (4, 4) for the resolver that moves the grasp point (``offset``
    ahead of the end effector) to ``point`` while the z axis turns to ``approach``: the
    origin goes ``offset`` behind ``point`` along the CURRENT z axis, so the position task
    places the grasp point itself whatever the remaining pointing error."""
    target = np.eye(4)
    target[:3, :3] = align_z(current[:3, :3], approach)
    target[:3, 3] = point - offset * current[:3, 2]
    return target


def grasp_point(pose: FloatArray, offset: float) -> FloatArray:
    """The point ``offset`` (m) ahead of the end effector along its z axis, where a
    grasped berry sits between the fingers."""
    return pose[:3, 3] + offset * pose[:3, 2]


def pointing_error(pose: FloatArray, approach: FloatArray) -> float:
    """Angle (rad) between the gripper's z axis and ``approach``."""
    return float(np.arccos(np.clip(pose[:3, 2] @ approach, -1.0, 1.0)))
