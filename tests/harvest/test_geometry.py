"""Target poses, approach cone, clearance and the simulated bush."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm import PolynomialCurve, SoftArm
from softarm.harvest.control.clearance import CANE_RADIUS, Clearance
from softarm.harvest.control.ik import cone_axes
from softarm.harvest.machine.targets import align_z, grasp_point, pointing_error, tool_pose
from softarm.sim.bush import Bush

Y = np.array([0.0, 1.0, 0.0])


@pytest.mark.parametrize("seed", range(5))
def test_align_z_turns_z_onto_the_axis_by_the_smallest_rotation(seed: int) -> None:
    rng = np.random.default_rng(seed)
    r = Rotation.random(random_state=seed).as_matrix()
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    out = align_z(r, axis)
    assert np.allclose(out[:, 2], axis, atol=1e-12)
    assert np.allclose(out.T @ out, np.eye(3), atol=1e-12)
    turn = Rotation.from_matrix(out @ r.T).magnitude()
    assert turn == pytest.approx(np.arccos(np.clip(r[:, 2] @ axis, -1, 1)), abs=1e-9)


def test_align_z_handles_the_antiparallel_axis() -> None:
    out = align_z(np.eye(3), np.array([0.0, 0.0, -1.0]))
    assert np.allclose(out[:, 2], [0, 0, -1]) and np.isclose(np.linalg.det(out), 1.0)


def test_tool_pose_places_the_grasp_point_once_the_axis_is_reached() -> None:
    current = np.eye(4)
    current[:3, :3] = align_z(np.eye(3), Y)
    point = np.array([0.1, 0.4, 0.3])
    target = tool_pose(current, point, Y, 0.03)
    assert np.allclose(grasp_point(target, 0.03), point)
    assert pointing_error(target, Y) < 1e-12


def test_cone_axes_are_unit_and_inside_the_cone() -> None:
    axes = cone_axes(Y, 20.0)
    assert np.allclose(axes[0], Y) and len(axes) == 17
    assert np.allclose(np.linalg.norm(axes, axis=1), 1.0)
    angles = np.degrees(np.arccos(np.clip(axes @ Y, -1, 1)))
    assert angles.max() == pytest.approx(20.0) and sorted(set(np.round(angles, 6))) == [0, 10, 20]


def test_clearance_is_negative_through_the_arm_and_grows_away_from_it() -> None:
    arm = SoftArm.blackberry()
    q = np.full(9, 0.0167)
    z = arm.forward(q)[2, 3] / 2  # halfway up the straight arm
    near = Clearance(arm, [_line([0.0, -0.1, z], [0.0, 0.1, z])], 0.03)  # through the arm
    far = Clearance(arm, [_line([0.2, -0.1, z], [0.2, 0.1, z])], 0.03)
    assert near.gap(q) < 0.0 < far.gap(q)
    assert far.gap(q) == pytest.approx(0.2 - far.body.widest - CANE_RADIUS, abs=0.02)
    assert Clearance(arm, [], 0.03).gap(q) == np.inf
    assert far.path_gap(q, np.zeros(9)) <= min(far.gap(q), far.gap(np.zeros(9)))


def _line(a: list[float], b: list[float]) -> PolynomialCurve:
    a_, b_ = np.array(a), np.array(b)
    return PolynomialCurve(np.column_stack([a_, b_ - a_]), (0.0, 1.0))


def test_bush_is_deterministic_reachable_and_its_canes_clear_the_approaches() -> None:
    arm = SoftArm.blackberry()
    a, b = Bush.generate(arm, 6, 7), Bush.generate(arm, 6, 7)
    assert [x.position.tolist() for x in a.berries] == [x.position.tolist() for x in b.berries]
    assert Bush.generate(arm, 6, 8).berries[0].position.tolist() != a.berries[0].position.tolist()
    for berry in a.berries:
        pose = arm.forward(berry.q)
        assert np.allclose(pose[:3, 3] + 0.03 * pose[:3, 2], berry.position)  # FK, not guessed
        assert pointing_error(pose, Y) <= np.radians(20.0)
        assert np.all(berry.q >= arm.lower) and np.all(berry.q <= arm.upper)
    canes = np.concatenate([c.points(200) for c in a.branches])
    for berry in a.berries:  # straight +Y approach line, 15 cm to 2 cm past the berry
        line = berry.position + np.outer(np.linspace(-0.15, 0.02, 200), Y)
        d = np.linalg.norm(canes[:, None] - line[None], axis=2).min()
        assert d >= 0.044
    spacing = min(
        np.linalg.norm(p.position - q.position)
        for i, p in enumerate(a.berries)
        for q in a.berries[i + 1 :]
    )
    assert spacing >= 0.06
