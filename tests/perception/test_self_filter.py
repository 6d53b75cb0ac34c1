"""The robot self-filter's parts cover the marker body chosen: the cube's box as before,
and the frustum's plates that lean out beyond it; C1's cane points seen only through the
rig (its outline at rest) are left out of the fit."""

from __future__ import annotations

import numpy as np
import pytest

import softarm
import softarm.perception.c1 as c1_module
from softarm.errors import NonFiniteError, ParameterError, ShapeError
from softarm.harvest_config import HarvestConfig
from softarm.perception.c1 import StereoC1
from softarm.perception.self_filter import (
    SELF_MARGIN,
    a_cane,
    behind_rig,
    rig_outline,
    rig_parts,
)
from softarm.vision.camera_model import CameraModel
from softarm.vision.marker_body import marker_body, panel_corners
from softarm.vision.stereo_camera import StereoCamera


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


def _frustum_at_rest() -> tuple[softarm.SoftArm, np.ndarray, np.ndarray]:
    """The arm, its frustum's outline at rest (rig_outline) and the body's centre."""
    arm, body = softarm.SoftArm.blackberry(), marker_body("frustum", 0.08)
    T_ee_cube = np.eye(4)
    T_ee_cube[2, 3] = -0.05
    rest = np.zeros(arm.n_actuators)
    centre = (arm.forward(rest) @ T_ee_cube)[:3, 3]
    return arm, rig_outline(arm, rest, T_ee_cube, body), centre


def test_a_point_is_behind_the_rig_only_where_its_sight_line_crosses_it() -> None:
    outline = np.array([[0.0, 0.0, 0.5, 0.05]])
    eye = np.zeros((1, 3))
    points = np.array(
        [[0.0, 0.0, 0.8], [0.0, 0.0, 0.5], [0.0, 0.0, 0.3], [0.2, 0.0, 0.8], [0.0, 0.0, -0.8]]
    )
    assert behind_rig(points, eye, outline).tolist() == [True, True, False, False, False]
    # The margin widens the outline: a sight line 55 mm off its centre.
    grazing = np.array([[0.0, 0.055 * 0.8 / 0.5, 0.8]])
    assert not behind_rig(grazing, eye, outline, margin=0.0)[0]
    assert behind_rig(grazing, eye, outline, margin=0.01)[0]


@pytest.mark.parametrize(
    ("points", "eyes", "outline", "margin", "error", "names"),
    [
        (np.zeros((2, 2)), np.zeros((1, 3)), np.ones((1, 4)), 0.01, ShapeError, "points"),
        (np.zeros((2, 3)), np.zeros((1, 2)), np.ones((1, 4)), 0.01, ShapeError, "eyes"),
        (np.zeros((2, 3)), np.zeros((1, 3)), np.ones((1, 3)), 0.01, ShapeError, "outline"),
        (
            np.full((2, 3), np.nan),
            np.zeros((1, 3)),
            np.ones((1, 4)),
            0.01,
            NonFiniteError,
            "points",
        ),
        (np.zeros((2, 3)), np.zeros((1, 3)), np.ones((1, 4)), -0.01, ParameterError, "margin"),
    ],
)
def test_bad_inputs_to_behind_rig_are_named(
    points: np.ndarray,
    eyes: np.ndarray,
    outline: np.ndarray,
    margin: float,
    error: type,
    names: str,
) -> None:
    with pytest.raises(error, match=names):
        behind_rig(points, eyes, outline, margin)


def test_the_outline_covers_the_frustums_plates_and_the_tube() -> None:
    arm, outline, centre = _frustum_at_rest()
    body = marker_body("frustum", 0.08)
    T_ee_cube = np.eye(4)
    T_ee_cube[2, 3] = -0.05
    pose = arm.forward(np.zeros(arm.n_actuators)) @ T_ee_cube
    corners = panel_corners(body).reshape(-1, 3) @ pose[:3, :3].T + pose[:3, 3]
    gaps = np.linalg.norm(corners[:, None, :] - outline[None, :, :3], axis=2) - outline[:, 3]
    assert gaps.min(axis=1).max() <= 1e-9  # every plate corner inside some sphere
    tube = np.asarray(arm.backbone(np.zeros(arm.n_actuators), 7))
    gaps = np.linalg.norm(tube[:, None, :] - outline[None, :, :3], axis=2) - outline[:, 3]
    assert gaps.min(axis=1).max() < 0.0
    assert np.linalg.norm(outline[:, :3] - centre, axis=1).min() < 0.02


def _line(start: np.ndarray, end: np.ndarray, n: int = 200) -> np.ndarray:
    points = start + np.linspace(0.0, 1.0, n)[:, None] * (end - start)
    return np.column_stack([points, np.full(n, 0.005)])


def test_cane_points_seen_through_the_frustum_are_not_fitted_as_a_cane(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The frustum's own pixels (its plates' ink and edges), matched by C1's stereo at
    some wrong depth, land behind it, far from its parts: without the outline they are
    fitted as a phantom cane that the parts' margin (a_cane) keeps."""
    _, outline, centre = _frustum_at_rest()
    T_base_left = np.eye(4)
    T_base_left[:3, 3] = (0.72, -0.45, 0.54)  # where the row's C1 stands
    T_left_right = np.eye(4)
    T_left_right[0, 3] = 0.12
    camera = CameraModel.ideal(900.0, 1280, 720)
    stereo = StereoCamera(camera, camera, T_base_left, T_left_right)
    sight = centre - T_base_left[:3, 3]
    sight /= np.linalg.norm(sight)
    across = np.cross(sight, (0.0, 0.0, 1.0))
    across /= np.linalg.norm(across)
    behind = centre + 0.25 * sight  # a phantom 25 cm behind the body, 8 cm long
    aside = centre + 0.3 * across  # a cane beside the body, in plain view
    phantom = _line(behind - 0.04 * across, behind + 0.04 * across)
    up = np.array([0.0, 0.0, 0.1])
    cane = _line(aside - up, aside + up)
    monkeypatch.setattr(c1_module, "cane_points", lambda *_: np.vstack([phantom, cane]))
    parts = _parts("frustum")
    blank = np.zeros((720, 1280, 3), np.uint8)

    def fitted(with_outline: bool) -> list[np.ndarray]:
        c1 = StereoC1(stereo, lambda: (blank, blank))
        c1.fit_canes(parts, 2.0, outline if with_outline else None)
        return [f.points[:, :3].mean(axis=0) for f in c1.bush_map.canes]

    def near(middles: list[np.ndarray], point: np.ndarray) -> bool:
        return any(np.linalg.norm(m - point) < 0.02 for m in middles)

    before = fitted(False)
    assert near(before, behind) and near(before, aside)
    after = fitted(True)
    assert not near(after, behind) and near(after, aside)
