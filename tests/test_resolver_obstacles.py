"""Obstacles as the lowest-priority task of the resolver (issue 9 item 4): the repulsion
of planning paper eq. (9) on exact closest points of the whole body (arcs, plates,
gripper), in the null space of position AND orientation."""

from __future__ import annotations

import numpy as np
import pytest

import softarm
from softarm import Gains, PolynomialCurve, Resolver, Segment
from softarm.errors import InputError, ParameterError, SoftarmError

ARM = softarm.SoftArm.blackberry()
Q = np.array([0.010, 0.022, 0.015, 0.020, 0.012, 0.008, 0.015, 0.020, 0.012])
POSE = ARM.forward(Q)


def near_cane(q: np.ndarray, section: int = 1, gap: float = 0.055) -> Segment:
    """A straight cane crossing the backbone's normal plane at the middle of ``section``,
    ``gap`` m from it."""
    frames = ARM.frames(q)
    mid, _ = ARM.point(q, section, 0.5)
    z = frames[section][:3, 2]
    side = np.cross(z, [0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    c = mid + gap * side
    along = np.cross(z, side)
    return Segment(c - 0.2 * along, c + 0.2 * along)


def body_gap(q: np.ndarray, cane: object, radius: float) -> float:
    """Exact backbone (arcs only) distance minus ``radius``."""
    return softarm.closest(ARM, q, cane).distance - radius


@pytest.mark.parametrize("mode", ["hybrid", "position", "orientation"])
def test_repulsion_stays_in_the_null_space_of_the_tasks(mode: str) -> None:
    gains = Gains(lag_periods=0.0)
    cane = near_cane(Q)
    res = Resolver(ARM, mode, gains)
    # Zero pose errors: the tasks ask for nothing and the smooth schedule turns the
    # joint-limit term off, so the whole step is the projected repulsion.
    r = res.step(Q, POSE, obstacles=[cane])
    dq = r.q - Q
    assert np.linalg.norm(dq) > 1e-5, "the cane is within the influence distance"
    assert r.clearance < gains.influence_distance
    j = ARM.jacobian(Q)
    mask = np.array(gains.axis_mask)
    if mode in ("hybrid", "position"):
        assert np.linalg.norm(j[:3] @ dq) < 1e-3 * np.linalg.norm(dq)
    if mode in ("hybrid", "orientation"):
        assert np.linalg.norm((j[3:] @ dq)[mask]) < 1e-3 * np.linalg.norm(dq)
    # And the step moves the body away from the cane.
    assert body_gap(r.q, cane, 0.0) > body_gap(Q, cane, 0.0)


def test_repulsion_pushes_off_and_the_pose_holds_in_closed_iteration() -> None:
    cane = near_cane(Q, gap=0.05)
    res = Resolver(ARM, "hybrid", Gains(lag_periods=0.0))
    q = Q.copy()
    for _ in range(60):
        q = res.step(q, POSE, obstacles=[cane]).q
    assert body_gap(q, cane, 0.0) > body_gap(Q, cane, 0.0) + 0.003
    final = ARM.forward(q)
    assert np.linalg.norm(final[:3, 3] - POSE[:3, 3]) < 1e-3


def test_far_obstacles_change_nothing_and_repulsion_is_never_scheduled_off() -> None:
    res = Resolver(ARM, "hybrid")
    far = Segment(np.array([2.0, 2.0, 0.0]), np.array([2.0, 2.0, 1.0]))
    a = res.step(Q, POSE, obstacles=[far])
    b = res.step(Q, POSE)
    np.testing.assert_array_equal(a.q, b.q)
    assert a.clearance == np.inf
    # At the target (zero error) a near cane still repels.
    assert np.any(res.step(Q, POSE, obstacles=[near_cane(Q)]).q != Q)


def test_every_obstacle_form_is_accepted() -> None:
    cane = near_cane(Q)
    a, b = np.asarray(cane.a), np.asarray(cane.b)
    coeffs = np.stack([a, b - a]).T  # F(u) = a + (b - a) u, (3, 2)
    forms: list[object] = [
        cane,
        [cane],
        (cane,),
        PolynomialCurve(coeffs, (0.0, 1.0)),
        softarm.PointCloud(np.linspace(a, b, 50)),
        0.5 * (a + b),
        [0.5 * (a + b), cane],
    ]
    res = Resolver(ARM, "hybrid", Gains(lag_periods=0.0))
    for ob in forms:
        r = res.step(Q, POSE, obstacles=ob)
        assert np.linalg.norm(r.q - Q) > 1e-6, ob
    sol = res.solve(Q, POSE, obstacles=[cane], max_steps=20)
    assert np.all(np.isfinite(sol.q))


def test_the_gripper_and_plates_repel_too() -> None:
    # A cane crossing the gripper's axis 2 cm behind the end-effector origin: the arcs are
    # farther than the influence distance, the gripper is not.
    z, x = POSE[:3, 2], POSE[:3, 0]
    c = POSE[:3, 3] - 0.02 * z + 0.045 * x
    y = np.cross(z, x)
    cane = Segment(c - 0.1 * y, c + 0.1 * y)
    g = Gains(lag_periods=0.0, influence_distance=0.025)
    arcs = softarm.closest(ARM, Q, cane)
    radius = Resolver(ARM).body.section_radii[arcs.section] + g.obstacle_radius
    assert arcs.distance - radius > 0.025
    r = Resolver(ARM, "hybrid", g).step(Q, POSE, obstacles=[cane])
    assert r.clearance < 0.025
    # The gripper is rigid with the end effector: with the pose held (hybrid) it can only
    # turn about the uncontrolled y axis; with the orientation free it is pushed off.
    r = Resolver(ARM, "position", g).step(Q, POSE[:3, 3], obstacles=[cane])
    assert np.linalg.norm(r.q - Q) > 1e-7


@pytest.mark.parametrize(
    ("obstacles", "error"),
    [
        ("cane", InputError),
        ([object()], InputError),
        ([np.array([0.1, np.nan, 0.3])], SoftarmError),
        (np.zeros((2, 2)), SoftarmError),
        (3.0, InputError),
    ],
)
def test_bad_obstacles_are_typed_errors(obstacles: object, error: type) -> None:
    with pytest.raises(error):
        Resolver(ARM, "hybrid").step(Q, POSE, obstacles=obstacles)
    with pytest.raises(error):
        Resolver(ARM, "hybrid").solve(Q, POSE, obstacles=obstacles)


def test_conventional_mode_rejects_obstacles() -> None:
    with pytest.raises(ParameterError, match="obstacles"):
        Resolver(ARM, "conventional").step(Q, POSE, obstacles=[near_cane(Q)])
