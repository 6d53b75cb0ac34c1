"""The robot self-filter's parts cover the marker body chosen: the cube's box as before,
and the frustum's plates that lean out beyond it."""

from __future__ import annotations

import numpy as np

import softarm
from softarm.harvest_config import HarvestConfig
from softarm.perception.self_filter import SELF_MARGIN, a_cane, rig_parts
from softarm.vision.marker_body import marker_body, panel_corners


def _parts(body: str | None) -> np.ndarray:
    T_ee_cube = np.eye(4)
    T_ee_cube[2, 3] = -0.05
    chosen = None if body is None else marker_body(body, 0.08)
    return rig_parts(softarm.SoftArm.blackberry(), HarvestConfig(), T_ee_cube, None, chosen)


def test_the_cube_is_the_box_it_always_was() -> None:
    assert np.array_equal(_parts(None), _parts("cube"))


def test_a_curve_along_a_frustum_plate_is_the_rig_not_a_cane() -> None:
    arm, body = softarm.SoftArm.blackberry(), marker_body("frustum", 0.08)
    T_ee_cube = np.eye(4)
    T_ee_cube[2, 3] = -0.05
    pose = arm.forward(np.zeros(arm.n_actuators)) @ T_ee_cube
    far = max(panel_corners(body).reshape(-1, 3), key=lambda p: float(np.linalg.norm(p)))
    tip = pose[:3, 3] + pose[:3, :3] @ far  # a plate's outermost corner, at rest
    outward = (tip - pose[:3, 3]) / np.linalg.norm(tip - pose[:3, 3])
    curve = tip + np.linspace(0.0, 0.5 * SELF_MARGIN, 5)[:, None] * outward
    assert a_cane(curve, _parts(None), reach=2.0)  # the cube's box alone misses it
    assert not a_cane(curve, _parts("frustum"), reach=2.0)
