import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm.errors import InputError, ParameterError, PoseError
from softarm.vision import PoseLowPassFilter
from softarm.vision.poses import rotation_angle


def _pose(rotvec: list[float], pos: list[float]) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
    pose[:3, 3] = pos
    return pose


def test_step_response_has_time_constant_one_over_cutoff() -> None:
    filt = PoseLowPassFilter(cutoff=10.0)
    filt.update(np.eye(4), 0.0)
    target = _pose([0.0, 0.0, 2.0], [1.0, 0.0, 0.0])  # 2 rad about z, 1 m along x
    dt = 1e-3
    for k in range(1, 101):  # up to t = 0.1 s = one time constant
        out = filt.update(target, k * dt)
    frac = 1 - np.exp(-1.0)
    assert out[0, 3] == pytest.approx(frac, rel=1e-9)
    assert rotation_angle(np.eye(4), out) == pytest.approx(2.0 * frac, rel=1e-9)


def test_result_independent_of_frame_rate() -> None:
    target = _pose([0.3, -0.2, 0.5], [0.1, 0.2, 0.3])
    outs = []
    for dt in (1e-3, 1e-2, 5e-2):
        filt = PoseLowPassFilter(10.0)
        filt.update(np.eye(4), 0.0)
        for k in range(1, round(0.2 / dt) + 1):
            out = filt.update(target, k * dt)
        outs.append(out)
    np.testing.assert_allclose(outs[0], outs[1], atol=1e-9)
    np.testing.assert_allclose(outs[0], outs[2], atol=1e-9)


def test_stays_on_so3_under_noisy_rotations() -> None:
    rng = np.random.default_rng(0)
    filt = PoseLowPassFilter()
    for k in range(500):
        meas = _pose(list(rng.normal(scale=2.0, size=3)), list(rng.normal(size=3)))
        out = filt.update(meas, k / 30)
        rot = out[:3, :3]
        np.testing.assert_allclose(rot.T @ rot, np.eye(3), atol=1e-12)
        assert np.linalg.det(rot) == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_array_equal(out[3], [0, 0, 0, 1])


def test_takes_the_short_way_round() -> None:
    filt = PoseLowPassFilter(10.0)
    filt.update(_pose([0, 0, np.pi - 0.1], [0, 0, 0]), 0.0)
    out = filt.update(_pose([0, 0, -np.pi + 0.1], [0, 0, 0]), 1.0)  # 0.2 rad apart
    assert rotation_angle(out, _pose([0, 0, -np.pi + 0.1], [0, 0, 0])) < 1e-3


def test_bad_input() -> None:
    with pytest.raises(ParameterError, match="cutoff"):
        PoseLowPassFilter(0.0)
    filt = PoseLowPassFilter()
    with pytest.raises(PoseError, match="measurement"):
        filt.update(np.ones((4, 4)), 0.0)
    filt.update(np.eye(4), 1.0)
    with pytest.raises(InputError, match="time"):
        filt.update(np.eye(4), 0.5)
    filt.reset()
    assert filt.pose is None
