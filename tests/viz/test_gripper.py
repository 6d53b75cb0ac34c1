"""The gripper's outline: fingers around the grasp point, carried by the pose."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import ParameterError, ShapeError
from softarm.viz.gripper import gripper_outline, gripper_polylines


def test_fingers_reach_past_the_grasp_point_on_both_sides() -> None:
    palm, left, right = gripper_outline(0.03)
    assert np.allclose(palm[:, 2], 0.0)
    for finger, side in ((left, -1.0), (right, 1.0)):
        assert finger[-1, 2] > 0.03  # past the grasp point along the approach axis
        assert np.all(side * finger[:, 0] > 0.0)  # each finger on its own side of it


def test_polylines_follow_the_pose() -> None:
    pose = np.eye(4)
    pose[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]  # 90 degrees about z
    pose[:3, 3] = [0.1, 0.2, 0.3]
    local = gripper_outline(0.03)
    world = gripper_polylines(pose, 0.03)
    for a, b in zip(local, world, strict=True):
        assert np.allclose(b, a @ pose[:3, :3].T + pose[:3, 3])


@pytest.mark.parametrize("offset", [0.0, -0.01, float("nan")])
def test_bad_offset_is_a_parameter_error(offset: float) -> None:
    with pytest.raises(ParameterError, match="offset"):
        gripper_outline(offset)


def test_bad_pose_is_a_shape_error() -> None:
    with pytest.raises(ShapeError, match="pose"):
        gripper_polylines(np.eye(3))
