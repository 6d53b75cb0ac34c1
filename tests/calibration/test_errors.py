"""Bad input to calibrate() and Calibration gives typed errors naming the argument."""

import math

import numpy as np
import pytest

import softarm
from softarm.calibration import Calibration, calibrate
from softarm.calibration.excitation import excitation_set
from softarm.errors import (
    ConfigError,
    InputError,
    NonFiniteError,
    ParameterError,
    PoseError,
    ShapeError,
)

ARM = softarm.SoftArm.blackberry()


def _data(n: int = 30) -> tuple[np.ndarray, np.ndarray]:
    c = np.random.default_rng(0).uniform(0.0, 0.03, (n, 9))
    return c, ARM.forward_batch(c)


def test_wrong_command_shape() -> None:
    c, p = _data()
    with pytest.raises(ShapeError, match="commands"):
        calibrate(ARM, c[:, :8], p)


def test_wrong_pose_shape() -> None:
    c, p = _data()
    with pytest.raises(ShapeError, match="poses"):
        calibrate(ARM, c, p[:-1])


def test_nan_commands_and_poses() -> None:
    c, p = _data()
    c[3, 2] = np.nan
    with pytest.raises(NonFiniteError, match="commands"):
        calibrate(ARM, c, p)
    c, p = _data()
    p[1, 0, 3] = np.nan
    with pytest.raises(NonFiniteError, match="poses"):
        calibrate(ARM, c, p)


def test_not_a_rigid_transform() -> None:
    c, p = _data()
    p[4, :3, :3] *= 2.0
    with pytest.raises(PoseError, match=r"poses\[4\]"):
        calibrate(ARM, c, p)


def test_fewer_samples_than_parameters() -> None:
    c, p = _data(20)  # 21 parameters
    with pytest.raises(ShapeError, match="fewer than the 21"):
        calibrate(ARM, c, p)


def test_bad_options_and_arm() -> None:
    c, p = _data()
    with pytest.raises(ParameterError, match="position_noise"):
        calibrate(ARM, c, p, position_noise=0.0)
    with pytest.raises(ParameterError, match="prior"):
        calibrate(ARM, c, p, prior=-1.0)
    with pytest.raises(InputError, match="nominal_arm"):
        calibrate("blackberry", c, p)  # type: ignore[arg-type]
    assert isinstance(ShapeError("x"), ValueError)


def test_exact_data_is_fitted_exactly() -> None:
    c, p = _data()
    cal = calibrate(ARM, c, p, prior=math.inf)
    assert cal.fit.position_max_mm < 1e-6
    np.testing.assert_allclose(cal.actuator_gain, 1.0, atol=1e-8)


def test_predict_rejects_bad_commands() -> None:
    c, p = _data()
    cal = calibrate(ARM, c, p)
    with pytest.raises(ShapeError, match="commands"):
        cal.predict(np.zeros(9))
    with pytest.raises(NonFiniteError, match="commands"):
        cal.predict(np.full((1, 9), np.inf))


def test_load_rejects_malformed_model(tmp_path) -> None:
    with pytest.raises(ConfigError, match="no such file"):
        Calibration.load(tmp_path / "absent.toml")
    c, p = _data()
    text = calibrate(ARM, c, p).to_toml()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("gain = [", "gain = [-1.0, "))
    with pytest.raises(ConfigError, match=r"actuators\.gain"):
        Calibration.load(bad)
    bad.write_text(text.replace("radius = ", "radius = -", 1))
    with pytest.raises(ConfigError, match=r"arm\.sections\[0\]"):
        Calibration.load(bad)


def test_excitation_set_stays_inside_the_limits() -> None:
    c = excitation_set(ARM, 100, seed=3)
    assert c.shape == (100, 9)
    assert np.all(c >= 0.1 * ARM.upper - 1e-12) and np.all(c <= 0.95 * ARM.upper + 1e-12)
    with pytest.raises(ParameterError, match="n = 101"):
        excitation_set(ARM, 101)
