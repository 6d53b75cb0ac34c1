import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm.errors import InputError, NonFiniteError, ShapeError
from softarm.vision import register_points


def _random_pose(rng: np.random.Generator) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()
    pose[:3, 3] = rng.normal(size=3)
    return pose


def test_recovers_known_transform_exactly() -> None:
    rng = np.random.default_rng(1)
    for _ in range(20):
        pose = _random_pose(rng)
        src = rng.normal(size=(6, 3))
        dst = src @ pose[:3, :3].T + pose[:3, 3]
        res = register_points(src, dst)
        np.testing.assert_allclose(res.transform, pose, atol=1e-10)
        assert res.rms < 1e-10
        assert res.residuals.shape == (6,)


def test_noise_gives_residual_of_noise_size() -> None:
    rng = np.random.default_rng(2)
    pose = _random_pose(rng)
    src = rng.uniform(-0.2, 0.2, size=(200, 3))
    sigma = 1e-3
    dst = src @ pose[:3, :3].T + pose[:3, 3] + rng.normal(0, sigma, size=src.shape)
    res = register_points(src, dst)
    # RMS of a 3-D isotropic error, less the 6 fitted degrees of freedom.
    assert res.rms == pytest.approx(sigma * np.sqrt(3 * (200 - 2) / 200), rel=0.1)
    assert np.linalg.norm(res.transform[:3, 3] - pose[:3, 3]) < 5 * sigma / np.sqrt(200) * 10


def test_mirrored_target_still_gives_a_proper_rotation() -> None:
    rng = np.random.default_rng(3)
    src = rng.normal(size=(10, 3))
    dst = src * [1.0, 1.0, -1.0]  # a reflection: the best orthogonal map has det -1
    res = register_points(src, dst)
    rot = res.transform[:3, :3]
    np.testing.assert_allclose(rot.T @ rot, np.eye(3), atol=1e-12)
    assert np.linalg.det(rot) == pytest.approx(1.0)
    assert res.rms > 0.1  # a rotation cannot fit a mirror image


def test_planar_points_are_registered() -> None:
    rng = np.random.default_rng(4)
    pose = _random_pose(rng)
    src = np.c_[rng.normal(size=(5, 2)), np.zeros(5)]
    dst = src @ pose[:3, :3].T + pose[:3, 3]
    np.testing.assert_allclose(register_points(src, dst).transform, pose, atol=1e-10)


def test_weights_ignore_an_outlier() -> None:
    rng = np.random.default_rng(5)
    pose = _random_pose(rng)
    src = rng.normal(size=(8, 3))
    dst = src @ pose[:3, :3].T + pose[:3, 3]
    dst[0] += 5.0
    w = np.ones(8)
    w[0] = 0.0
    np.testing.assert_allclose(register_points(src, dst, w).transform, pose, atol=1e-10)


@pytest.mark.parametrize(
    ("src", "dst", "err"),
    [
        (np.zeros((4, 2)), np.zeros((4, 2)), ShapeError),
        (np.zeros((4, 3)), np.zeros((5, 3)), ShapeError),
        (np.zeros((2, 3)), np.zeros((2, 3)), ShapeError),
        (np.c_[np.arange(4.0), np.zeros((4, 2))], np.zeros((4, 3)), InputError),
        (np.full((4, 3), np.nan), np.zeros((4, 3)), NonFiniteError),
    ],
)
def test_bad_input(src: np.ndarray, dst: np.ndarray, err: type[Exception]) -> None:
    with pytest.raises(err, match=r"source|target|collinear"):
        register_points(src, dst)
