"""softarm.so3: the axioms of exp/log on SO(3), and the results of the hand-written copies
it replaced (tracker exp/log, the targets' Rodrigues turn, the experiments' orientation
error) unchanged."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from softarm import Resolver, SoftArm, so3
from softarm.experiments.common import orientation_error
from softarm.harvest.machine.targets import align_z

VEC = st.lists(st.floats(-1.0, 1.0, allow_nan=False), min_size=3, max_size=3).map(np.array)


def _scaled(v: np.ndarray, angle: float) -> np.ndarray:
    n = float(np.linalg.norm(v))
    return v if n < 1e-9 else v / n * angle


# --- the hand-written copies, kept here as the reference the toolkit must reproduce ---


def _old_exp(w: np.ndarray) -> np.ndarray:
    theta = float(np.linalg.norm(w))
    k = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if theta < 1e-12:
        return np.eye(3) + k
    a = math.sin(theta) / theta
    b = (1.0 - math.cos(theta)) / theta**2
    return np.eye(3) + a * k + b * (k @ k)


def _old_log(r: np.ndarray) -> np.ndarray:
    c = max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0))
    theta = math.acos(c)
    v = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    if theta < 1e-9:
        return 0.5 * v
    return theta / (2.0 * math.sin(theta)) * v


def _old_align_z(rotation: np.ndarray, axis: np.ndarray) -> np.ndarray:
    z = rotation[:, 2]
    v = np.cross(z, axis)
    c = float(np.clip(z @ axis, -1.0, 1.0))
    s = float(np.linalg.norm(v))
    if s < 1e-12:
        if c > 0:
            return rotation.copy()
        k = rotation[:, 0]
        return (2.0 * np.outer(k, k) - np.eye(3)) @ rotation
    k = v / s
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return (np.eye(3) + s * kx + (1.0 - c) * (kx @ kx)) @ rotation


@given(VEC, st.floats(0.0, 3.0))
def test_log_inverts_exp(v: np.ndarray, angle: float) -> None:
    w = _scaled(v, angle)
    np.testing.assert_allclose(so3.log(so3.exp(w)), w, atol=1e-12)


@given(VEC, st.floats(0.0, 3.1))
def test_exp_is_a_rotation_and_matches_the_old_copy(v: np.ndarray, angle: float) -> None:
    r = so3.exp(_scaled(v, angle))
    np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-12)
    assert np.linalg.det(r) == pytest.approx(1.0)
    np.testing.assert_allclose(r, _old_exp(_scaled(v, angle)), atol=1e-12)
    np.testing.assert_allclose(so3.log(r), _old_log(r), atol=1e-9)


@given(VEC, st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_rotations_about_one_axis_compose_by_adding_angles(
    v: np.ndarray, a: float, b: float
) -> None:
    if np.linalg.norm(v) < 1e-6:
        return
    k = v / np.linalg.norm(v)
    np.testing.assert_allclose(so3.exp(a * k) @ so3.exp(b * k), so3.exp((a + b) * k), atol=1e-12)
    np.testing.assert_allclose(so3.exp(-a * k), so3.exp(a * k).T, atol=1e-12)


@given(VEC, VEC)
def test_align_z_matches_the_old_rodrigues_turn(w: np.ndarray, axis: np.ndarray) -> None:
    if np.linalg.norm(axis) < 1e-6:
        return
    rotation = so3.exp(_scaled(w, 2.0))
    unit = axis / np.linalg.norm(axis)
    out = align_z(rotation, unit)
    np.testing.assert_allclose(out, _old_align_z(rotation, unit), atol=1e-9)
    np.testing.assert_allclose(out[:, 2], unit, atol=1e-9)


def test_align_z_turns_an_antiparallel_axis_about_the_current_x_axis() -> None:
    r = so3.exp([0.3, -0.2, 0.1])
    np.testing.assert_allclose(align_z(r, -r[:, 2]), _old_align_z(r, -r[:, 2]), atol=1e-12)
    assert so3.rotation_between([0, 0, 1.0], [0, 0, -1.0]) is None


def test_experiments_orientation_error_is_the_cores_and_equals_the_old_formula() -> None:
    arm = SoftArm.blackberry()
    judge = Resolver(arm, "hybrid")
    rng = np.random.default_rng(11)
    for _ in range(50):
        target, pose = np.eye(4), np.eye(4)
        target[:3, :3] = so3.exp(rng.normal(size=3))
        pose[:3, :3] = so3.exp(rng.normal(size=3) * 0.4) @ target[:3, :3]
        old = float(np.linalg.norm([1.0, 0.0, 1.0] * _old_log(target[:3, :3] @ pose[:3, :3].T)))
        got = orientation_error(judge, rng.uniform(0, 0.03, 9), target, pose)
        assert got == pytest.approx(old, abs=1e-12)


@given(VEC)
def test_quaternion_is_scipys_with_w_not_negative(w: np.ndarray) -> None:
    from scipy.spatial.transform import Rotation

    r = so3.exp(_scaled(w, 3.1))
    want = Rotation.from_matrix(r).as_quat()
    want = want if want[3] >= 0 else -want
    got = np.array(so3.quaternion_xyzw(r))
    np.testing.assert_allclose(got, want, atol=1e-12)


@pytest.mark.parametrize("axis", [(1.0, 0, 0), (0, 1.0, 0), (0, 0, 1.0), (1.0, 1.0, 0)])
def test_quaternion_of_half_turns_takes_each_branch(axis: tuple[float, ...]) -> None:
    unit = np.asarray(axis) / np.linalg.norm(axis)
    x, y, z, w = so3.quaternion_xyzw(so3.exp(np.pi * unit))
    np.testing.assert_allclose(np.abs([x, y, z]), np.abs(unit), atol=1e-12)
    assert abs(w) < 1e-12
