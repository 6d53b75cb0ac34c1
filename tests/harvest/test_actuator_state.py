"""The actuator owns what was sent and where the lag model puts the actuators."""

import math

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.hardware import SafePressureBank, SimulatedPressureBank
from softarm.harvest import SafeActuator
from softarm.units import METRES_PER_PSI


class _Plant:
    def __init__(self, n: int) -> None:
        self.psi = np.zeros(n)

    def command_pressures(self, psi: np.ndarray) -> None:
        self.psi = np.asarray(psi, dtype=np.float64).copy()

    def pressures(self) -> np.ndarray:
        return self.psi.copy()


class _Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def now(self) -> float:
        return self.t


def _actuator(rate: float = 100.0, **kwargs: object) -> tuple[SafeActuator, _Clock]:
    clock = _Clock()
    bank = SafePressureBank(
        SimulatedPressureBank(_Plant(3), 3), 70.0, rate, 0.5, clock.now, watchdog_thread=False
    )
    return SafeActuator(bank, now=clock.now, **kwargs), clock  # type: ignore[arg-type]


def test_sent_is_what_the_safety_layer_let_through() -> None:
    act, clock = _actuator(rate=100.0)  # 100 psi/s: 5 psi in a 50 ms period
    act.send(np.zeros(3))  # the safety layer's first command only starts its rate clock
    clock.t = 0.05
    sent = act.send(np.array([0.01, 0.001, 0.0]))  # 21 psi asked on channel 0
    assert sent[0] == pytest.approx(5.0 * METRES_PER_PSI)  # rate-limited
    assert sent[1] == pytest.approx(0.001)
    np.testing.assert_array_equal(sent, act.sent)
    act.vent("test")
    np.testing.assert_array_equal(act.sent, np.zeros(3))


def test_prediction_is_two_first_order_lags_in_series() -> None:
    tau, filt, period = 0.8, 0.1, 0.05
    act, clock = _actuator(rate=1000.0, lag=(tau, period), sensor_lag_s=filt)
    q = np.array([0.01, 0.02, 0.005])
    y1 = np.zeros(3)
    y2 = np.zeros(3)
    act.send(np.zeros(3))  # the safety layer's first command only starts its rate clock
    for k in range(1, 80):
        clock.t = k * period
        act.send(q)
        # The closed forms of each zero-order-hold period (the regulator, then the filter).
        y1 = q + (y1 - q) * math.exp(-period / tau)
        y2 = y1 + (y2 - y1) * math.exp(-period / filt)
    clock.t = 80 * period
    np.testing.assert_allclose(act.plant_q, y2, rtol=1e-12, atol=1e-15)
    # Nothing sent for 2 s (a grasp): the model goes on with the command held.
    clock.t += 2.0
    for _ in range(40):
        y1 = q + (y1 - q) * math.exp(-period / tau)
        y2 = y1 + (y2 - y1) * math.exp(-period / filt)
    np.testing.assert_allclose(act.plant_q, y2, rtol=1e-9, atol=1e-12)


def test_no_lag_no_prediction_and_a_lag_needs_a_clock() -> None:
    act, _ = _actuator()
    assert act.plant_q is None
    bank = act.bank
    with pytest.raises(ParameterError, match="lag"):
        SafeActuator(bank, lag=(0.5, 0.05))


def test_lead_speeds_a_first_order_regulator_up_by_one_plus_k() -> None:
    tau, period, k = 0.8, 0.05, 1.5
    act, clock = _actuator(rate=1000.0, lag=(tau, period), lead=k)
    act.send(np.zeros(3))
    q = np.array([0.005, 0.004, 0.0])  # boosted by 2.5x: inside the 50 psi a period allows
    a = math.exp(-period / tau)
    y = np.zeros(3)
    for n in range(1, 30):
        clock.t = n * period
        sent = act.send(q)
        np.testing.assert_allclose(sent, q, atol=1e-15)  # the target, not the boost
        clock.t = (n + 1) * period
        # ZOH of u = q + k (q - y) through the lag: y - q shrinks by a - (1 - a) k.
        y = q + (a - (1 - a) * k) * (y - q)
        np.testing.assert_allclose(act.plant_q, y, rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize(
    ("tau", "expected"), [(0.0, 0.0), (0.08, 0.5 * 0.5353 / 0.4647), (1.0, 1.5)]
)
def test_lead_gain_is_half_the_overshoot_free_bound_capped(tau: float, expected: float) -> None:
    from softarm.harvest.control.actuator import lead_gain

    assert lead_gain(tau, 0.05) == pytest.approx(expected, rel=1e-3)
    with pytest.raises(ParameterError):
        lead_gain(-1.0, 0.05)


def test_lead_is_scaled_as_one_vector_inside_the_range_and_rate() -> None:
    tau, k = 1.0, 1.5
    # A 100 ms period: 100 psi a period at 1000 psi/s, so the range binds first.
    act, clock = _actuator(rate=1000.0, lag=(tau, 0.1), lead=k)
    act.send(np.zeros(3))
    clock.t = 0.1
    q = np.array([0.03, 0.01, 0.0])  # 63 / 21 / 0 psi: the full boost would ask 157 psi
    act.send(q)
    wanted = q / METRES_PER_PSI
    boost = act.bank.last_sent - wanted
    full = k * wanted  # the lag model still at 0
    assert np.max(act.bank.last_sent) == pytest.approx(70.0)  # scaled to the range...
    np.testing.assert_allclose(boost / np.linalg.norm(boost), full / np.linalg.norm(full))
    np.testing.assert_allclose(act.sent, q, atol=1e-15)  # ...in the same direction
    # At 50 ms, 50 psi a period: the safety layer's rate bounds the boost alike.
    act2, clock2 = _actuator(rate=1000.0, lag=(tau, 0.05), lead=k)
    act2.send(np.zeros(3))
    clock2.t = 0.05
    act2.send(np.array([0.02, 0.005, 0.0]))  # 42 / 10.5 psi, boosts 63 / 15.75
    sent = act2.bank.last_sent
    assert sent[0] == pytest.approx(50.0)
    assert (sent[1] - 10.5) / (sent[0] - 42.0) == pytest.approx(10.5 / 42.0)


def test_in_flight_is_what_the_lag_model_still_expects() -> None:
    act, clock = _actuator(rate=1000.0, lag=(0.5, 0.05), sensor_lag_s=0.1)
    assert _actuator()[0].in_flight() is None
    act.send(np.zeros(3))
    q = np.array([0.01, 0.0, 0.002])
    clock.t = 0.05
    act.send(q)
    np.testing.assert_allclose(act.in_flight(), q, atol=1e-15)  # nothing arrived yet
    clock.t = 0.05 + 5.0  # ten time constants later, nothing more sent
    np.testing.assert_allclose(act.in_flight(), 0.0, atol=1e-6)
    np.testing.assert_allclose(act.plant_q, q, atol=1e-6)


def test_play_needs_the_lag_model_and_a_valid_width() -> None:
    with pytest.raises(ParameterError, match="play_m"):
        _actuator(play_m=0.002)
    with pytest.raises(ParameterError, match="play_m"):
        _actuator(lag=(0.5, 0.05), play_m=-0.002)


def test_with_play_plant_q_counts_no_motion_inside_the_band() -> None:
    # 5 psi of play (2.4 mm): risen and settled, a 1 mm step back is swallowed by the
    # band, so nothing is in flight and plant_q is the command itself.
    w = 5.0 * METRES_PER_PSI
    act, clock = _actuator(rate=1000.0, lag=(0.05, 0.05), play_m=w)
    q = np.full(3, 0.01)
    for k in range(60):
        clock.t = 0.05 * k
        act.send(q)
    clock.t = 0.05 * 60
    back = q - 0.001
    act.send(back)
    np.testing.assert_allclose(act.plant_q, back, atol=1e-12)
