"""softarm.closest and the obstacle classes, against a numpy oracle (dense sampling)."""

from __future__ import annotations

import numpy as np
import pytest

import softarm
from softarm import errors

CHAIN = softarm.ArcChain([1.0, 1.0, 1.0])
Q = np.array([1.0, 0.4, 0.3, 1.1, -0.6, 1.0, 0.9, 0.8, -2.0])


def dense_distance(arm: softarm.ArcChain, q: np.ndarray, pts: np.ndarray) -> float:
    """Slow oracle: dense backbone samples against dense obstacle samples."""
    bb = arm.backbone(q, 400)
    d = np.linalg.norm(bb[:, None, :] - pts[None, :, :], axis=2)
    return float(d.min())


def test_curve_distance_matches_dense_sampling() -> None:
    rng = np.random.default_rng(1)
    for _ in range(20):
        coeffs = rng.uniform(-1.0, 1.0, (3, 3))
        coeffs[:, 0] += [0.8, 0.2, 1.5]
        curve = softarm.PolynomialCurve(coeffs, (-1.0, 1.0))
        c = softarm.closest(CHAIN, Q, curve)
        dense = dense_distance(CHAIN, Q, curve(np.linspace(-1.0, 1.0, 1500)))
        assert c.distance <= dense + 1e-12
        assert c.distance > dense - 0.01
        # The reported points are real points at the reported parameters.
        p, _ = CHAIN.point(Q, c.section, c.s)
        np.testing.assert_allclose(p, c.arm_point, atol=1e-12)
        np.testing.assert_allclose(curve(c.u), c.obstacle_point, atol=1e-12)
        assert c.distance == pytest.approx(np.linalg.norm(c.arm_point - c.obstacle_point))


def test_types_and_attributes() -> None:
    curve = softarm.PolynomialCurve([[0.5, 0, 0], [0, 1, 0], [0, 0, 5]], (-2, 2))
    assert curve.degree == 2 and curve.u_range == (-2.0, 2.0)
    assert curve.coeffs.shape == (3, 3) and curve.coeffs.dtype == np.float64
    assert curve.sample(7).shape == (7, 3)
    c = softarm.closest(CHAIN, Q.tolist(), curve)
    assert isinstance(c.section, int)
    assert c.arm_point.dtype == np.float64 and c.arm_point.shape == (3,)
    with pytest.raises(AttributeError):
        c.distance = 1.0  # type: ignore[misc]


def test_segment_point_cloud_and_mesh() -> None:
    q = CHAIN.straight()
    seg = softarm.Segment([0.5, -1.0, 1.5], [0.5, 1.0, 1.5])
    c = softarm.closest(CHAIN, q, seg)
    assert c.distance == pytest.approx(0.5) and c.section == 1
    assert softarm.closest(CHAIN, q, [0.0, 0.3, 2.5]).distance == pytest.approx(0.3)
    rng = np.random.default_rng(2)
    pts = rng.uniform(-1.0, 1.0, (5000, 3)) + [1.2, 0.0, 1.5]
    cloud = softarm.PointCloud(pts)
    assert len(cloud) == 5000
    c = softarm.closest(CHAIN, Q, cloud)
    bb = CHAIN.backbone(Q, 2000)
    brute = np.linalg.norm(bb[:, None, :] - pts[None, ::10, :], axis=2).min()
    assert c.distance <= brute + 1e-12
    np.testing.assert_array_equal(pts[int(c.u)], c.obstacle_point)
    verts = np.array([[0.5, -1, 0.0], [0.5, 1, 0.0], [0.5, 0, 3.0]])
    mesh = softarm.TriangleMesh(verts, [[0, 1, 2]], tolerance=1e-4)
    m = softarm.closest(CHAIN, q, mesh)
    assert m.distance == pytest.approx(0.5, abs=2e-4) and m.distance <= 0.5


def test_crossing_curve_gives_zero() -> None:
    p, _ = CHAIN.point(Q, 1, 0.4)
    coeffs = np.column_stack([p, [1.0, -0.5, 0.2], [0.3, 0.1, -0.4]])
    assert softarm.closest(CHAIN, Q, softarm.PolynomialCurve(coeffs, (-1, 1))).distance < 1e-9


def test_errors_are_typed_and_name_the_argument() -> None:
    with pytest.raises(errors.ParameterError, match="u_range"):
        softarm.PolynomialCurve([[1.0], [0.0], [0.0]], (1.0, 1.0))
    with pytest.raises(errors.NonFiniteError, match="coeffs"):
        softarm.PolynomialCurve([[np.nan, 1.0], [0, 0], [0, 0]], (0.0, 1.0))
    with pytest.raises(errors.ShapeError, match="coeffs"):
        softarm.PolynomialCurve([[1.0, 2.0]], (0.0, 1.0))
    with pytest.raises(errors.ShapeError, match="points"):
        softarm.PointCloud(np.zeros((0, 3)))
    with pytest.raises(errors.NonFiniteError, match="b"):
        softarm.Segment([0, 0, 0], [np.inf, 0, 0])
    with pytest.raises(errors.InputError, match="obstacle"):
        softarm.closest(CHAIN, Q, "tree")
    with pytest.raises(errors.InputError, match="arm"):
        softarm.closest("arm", Q, [0, 0, 0])
    with pytest.raises(errors.ShapeError, match="q"):
        softarm.closest(CHAIN, Q[:4], [0, 0, 0])
    with pytest.raises(ValueError):
        softarm.TriangleMesh([[0, 0, 0]], [[0, 1, 2]])
