"""calibrate() recovers a perturbed constant-curvature plant (issue: +-6 % geometry and
gains, 0.1 mm / 0.1 deg noise, 80 samples). Seeds here are test seeds, not tuned on."""

import math

import numpy as np
import pytest

import softarm
from softarm.calibration import Calibration, PoseErrorStats, calibrate
from softarm.calibration.synthetic import synthetic_problem


@pytest.fixture(scope="module", params=[1000, 1001])
def fitted(request: pytest.FixtureRequest) -> tuple[object, Calibration]:
    pb = synthetic_problem(request.param)
    return pb, calibrate(pb.nominal, pb.fit_commands, pb.fit_poses)


def test_held_out_error_meets_the_goal(fitted) -> None:
    pb, cal = fitted
    st = cal.evaluate(pb.test_commands, pb.test_poses)
    nominal = PoseErrorStats.of(pb.nominal.forward_batch(pb.test_commands), pb.test_poses)
    assert st.position_median_mm <= 0.2
    assert st.position_p95_mm <= 0.5
    assert nominal.position_median_mm > 20 * st.position_median_mm


def test_recovers_the_parameters(fitted) -> None:
    pb, cal = fitted
    np.testing.assert_allclose(cal.actuator_gain, pb.true_gain, atol=0.01)
    for got, true in zip(cal.arm.sections, pb.true_arm.sections, strict=True):
        assert got.radius == pytest.approx(true.radius, rel=0.01)
        assert got.rest_length == pytest.approx(true.rest_length, rel=0.01)
        assert got.twist == pytest.approx(true.twist, abs=math.radians(0.5))


def test_fit_statistics_are_at_the_noise_level(fitted) -> None:
    _, cal = fitted
    assert cal.converged
    # |N(0, (0.1 mm)^2 I3)| has median 0.154 mm: the residual cannot be much below it.
    assert 0.1 < cal.fit.position_median_mm < 0.2
    assert cal.fit.samples == 80


def test_predict_and_model_toml_round_trip(fitted, tmp_path) -> None:
    pb, cal = fitted
    path = tmp_path / "model.toml"
    cal.save(path)
    back = Calibration.load(path)
    np.testing.assert_allclose(back.predict(pb.test_commands), cal.predict(pb.test_commands))
    assert back.fit == cal.fit
    assert softarm.calibration.load_model(path).sections == cal.arm.sections
    np.testing.assert_allclose(
        back.commands_for(cal.elongations(pb.test_commands[:3])), pb.test_commands[:3]
    )


def test_bias_recovers_a_bending_bias(tmp_path) -> None:
    # A plant whose actuators carry a zero-mean offset per section (a constant bend, as
    # gravity gives): the plain fit cannot express it, the bias fit can.
    pb = synthetic_problem(1002)
    offset = np.tile([0.002, -0.001, -0.001], 3)
    from softarm.calibration.synthetic import noisy

    rng = np.random.default_rng(5)
    poses = noisy(pb.true_arm.forward_batch(pb.fit_commands * pb.true_gain + offset), rng,
                  1e-4, math.radians(0.1))  # fmt: skip
    truth = pb.true_arm.forward_batch(pb.test_commands * pb.true_gain + offset)
    plain = calibrate(pb.nominal, pb.fit_commands, poses).evaluate(pb.test_commands, truth)
    cal = calibrate(pb.nominal, pb.fit_commands, poses, bias=True)
    biased = cal.evaluate(pb.test_commands, truth)
    assert biased.position_median_mm <= 0.2 < plain.position_median_mm
    np.testing.assert_allclose(cal.actuator_offset, offset, atol=3e-4)
    cal.save(tmp_path / "m.toml")
    back = Calibration.load(tmp_path / "m.toml")
    np.testing.assert_allclose(back.actuator_offset, cal.actuator_offset)
    np.testing.assert_allclose(back.predict(pb.test_commands), cal.predict(pb.test_commands))
