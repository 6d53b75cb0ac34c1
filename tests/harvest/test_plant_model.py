"""The controller's measurement-chain model against the simulated plant's own parts."""

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.harvest.control.plant_model import (
    PREDICTED_ALPHA_LAG_S,
    PREDICTED_ALPHA_MAX,
    PREDICTED_ALPHA_MIN,
    MeasurementModel,
    predicted_loop_alpha,
)
from softarm.sim.pressure import PressureDynamics


def test_follows_the_simulated_regulators() -> None:
    # The simulator's regulators (exact first-order ZOH), fed the same commands.
    n, tau, period = 2, 0.5, 0.05
    rng = np.random.default_rng(1)
    dyn = PressureDynamics(n, tau, 70.0)
    model = MeasurementModel(n, tau, period)  # 1 "m" per psi
    for _ in range(300):
        u = rng.uniform(0.0, 60.0, n) if rng.random() < 0.1 else dyn.pressure
        u = np.clip(u + rng.normal(0, 2.0, n), 0.0, 70.0)
        truth = dyn.advance(u, period)
        model.advance(u)
        np.testing.assert_allclose(model.measured, truth, rtol=1e-9, atol=1e-9)


def test_in_flight_is_the_motion_still_to_come() -> None:
    model = MeasurementModel(1, 1.0, 0.05)
    model.command(np.array([0.01]))
    model.advance(np.array([0.01]))
    assert model.in_flight()[0] == pytest.approx(0.01 * np.exp(-0.05), rel=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "arg"),
    [({"tau_s": -1.0}, "tau_s"), ({"filter_s": np.nan}, "filter_s")],
)  # fmt: skip
def test_bad_arguments_name_themselves(kwargs: dict, arg: str) -> None:
    args = {"n": 2, "tau_s": 0.5, "period_s": 0.05, **kwargs}
    with pytest.raises(ParameterError, match=arg):
        MeasurementModel(**args)


def test_predicted_loop_gain_is_cut_as_the_lag_grows() -> None:
    lags = np.linspace(0.0, 3.0, 61)
    alphas = [predicted_loop_alpha(float(s)) for s in lags]
    assert np.all(np.diff(alphas) <= 0)  # never larger on a slower chain
    assert alphas[0] == PREDICTED_ALPHA_MAX
    assert alphas[-1] == PREDICTED_ALPHA_MIN
    # Between the bounds the lag-gain product is the constant.
    assert predicted_loop_alpha(0.6) * 0.6 == pytest.approx(PREDICTED_ALPHA_LAG_S)
    # The simulated rig's quick plant (80 ms + the 0.1 s pose filter) and its slowest.
    assert predicted_loop_alpha(0.18) == PREDICTED_ALPHA_MAX
    assert predicted_loop_alpha(1.1) == PREDICTED_ALPHA_MIN


@pytest.mark.parametrize("lag", [-0.1, np.nan, np.inf])
def test_predicted_loop_gain_rejects_a_bad_lag(lag: float) -> None:
    with pytest.raises(ParameterError, match="lag_s"):
        predicted_loop_alpha(lag)


def test_the_arm_arrives_before_the_measurement_shows_it() -> None:
    # Arrival reads the regulators alone; the predictor reads them and the pose filter.
    model = MeasurementModel(1, 0.3, 0.05, filter_s=0.1)
    model.command(np.array([0.01]))
    for _ in range(10):
        model.advance(np.array([0.01]))
    arm, measured = model.arm_in_flight()[0], model.in_flight()[0]
    assert arm == pytest.approx(0.01 * np.exp(-0.5 / 0.3), rel=1e-12)  # 0.5 s at tau 0.3 s
    assert 0.0 < arm < measured < 0.01


def test_with_play_it_follows_the_simulated_regulators_and_play() -> None:
    # The simulator's regulators, then its play operator (sim.hysteresis), fed the same
    # commands: the model's measured output is the plant's elongation, to rounding.
    from softarm.sim.hysteresis import PlayHysteresis

    n, tau, period, width = 3, 0.3, 0.05, np.array([2.0, 5.0, 0.0])
    rng = np.random.default_rng(2)
    dyn = PressureDynamics(n, tau, 70.0)
    play = PlayHysteresis(width)
    model = MeasurementModel(n, tau, period, play_m=width)
    for _ in range(400):
        u = np.clip(dyn.pressure + rng.normal(0, 3.0, n), 0.0, 70.0)
        truth = play(dyn.advance(u, period))
        model.advance(u)
        np.testing.assert_allclose(model.measured, truth, rtol=1e-9, atol=1e-9)


def test_with_play_a_command_inside_the_band_has_nothing_in_flight() -> None:
    """The play's closed form: risen to q, the arm sits w/2 below it; a command back
    inside the band moves nothing; one beyond it moves the arm to the band's edge."""
    model = MeasurementModel(1, 0.0, 0.05, play_m=2.0)
    model.command(np.array([10.0]))
    model.advance(np.array([10.0]))
    assert model.measured[0] == pytest.approx(9.0)
    assert model.in_flight()[0] == pytest.approx(0.0)
    model.command(np.array([8.5]))  # down 1.5 < w: still in the band
    assert model.in_flight()[0] == pytest.approx(0.0)
    model.command(np.array([7.0]))  # down 3 > w: the arm follows to q + w/2
    assert model.in_flight()[0] == pytest.approx(-1.0)
    model.command(np.array([10.5]))  # up past where it sits: to q - w/2
    assert model.in_flight()[0] == pytest.approx(0.5)
    # Without play, the same commands are all in flight.
    bare = MeasurementModel(1, 0.0, 0.05)
    bare.command(np.array([10.0]))
    bare.advance(np.array([10.0]))
    bare.command(np.array([8.5]))
    assert bare.in_flight()[0] == pytest.approx(-1.5)


@pytest.mark.parametrize("play", [-1.0, np.nan, [1.0, 2.0], "wide"])
def test_a_bad_play_width_names_itself(play: object) -> None:
    with pytest.raises(ParameterError, match="play_m"):
        MeasurementModel(3, 0.1, 0.05, play_m=play)  # type: ignore[arg-type]
