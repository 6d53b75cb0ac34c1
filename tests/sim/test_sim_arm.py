"""The simulated plant: determinism, perturbation, pressure saturation and dynamics,
rate-independent hysteresis, the tracker's filter, and input errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softarm
from softarm.sim import PlantConfig, PlayHysteresis, PoseTracker, PressureDynamics, SimulatedArm

Q = np.full(9, 0.015)


def run(plant: SimulatedArm, commands: np.ndarray) -> np.ndarray:
    plant.reset(Q)
    return np.array([plant.apply(c, 0.05) for c in commands])


def test_deterministic_under_a_seed() -> None:
    cmds = np.random.default_rng(0).uniform(0, 0.03, (20, 9))
    a = run(SimulatedArm(seed=4), cmds)
    b = run(SimulatedArm(seed=4), cmds)
    c = run(SimulatedArm(seed=5), cmds)
    np.testing.assert_array_equal(a, b)
    assert np.abs(a - c).max() > 1e-4


def test_true_arm_is_not_the_model() -> None:
    plant = SimulatedArm(seed=1)
    model, true = plant.model, plant.true_arm
    bent = np.array([0.0, 0.02, 0.03, 0.01, 0.0, 0.03, 0.02, 0.03, 0.0])
    d = np.linalg.norm(model.forward(bent)[:3, 3] - true.forward(bent)[:3, 3])
    assert 1e-4 < d < 0.05
    for m, t in zip(model.sections, true.sections, strict=True):
        assert abs(t.radius / m.radius - 1) <= 0.03 + 1e-12
        assert abs(t.twist - m.twist) <= 0.03 + 1e-12


def test_pressure_saturates_at_zero_and_max() -> None:
    plant = SimulatedArm(seed=2)
    plant.reset(Q)
    for _ in range(60):
        plant.apply(np.r_[np.full(4, -0.05), np.full(5, 0.2)], 0.05)
    p = plant.pressure
    assert np.all(p >= 0.0) and np.all(p <= plant.config.max_psi)
    assert p[:4].max() < 1e-3 and p[4:].min() > plant.config.max_psi - 1e-3


def test_first_order_pressure_dynamics() -> None:
    d = PressureDynamics(1, tau=0.1)
    p = d.advance([50.0], 0.1)
    assert p[0] == pytest.approx(50.0 * (1 - math.exp(-1)))
    assert d.advance([50.0], 0.1)[0] == pytest.approx(50.0 * (1 - math.exp(-2)))
    with pytest.raises(softarm.ParameterError, match="tau"):
        PressureDynamics(1, tau=0.0)


def test_hysteresis_is_rate_independent_and_has_a_band() -> None:
    up = np.r_[np.linspace(0, 10, 11), np.linspace(10, 0, 11)]
    slow = np.r_[np.linspace(0, 10, 101), np.linspace(10, 0, 101)]
    h1, h2 = PlayHysteresis([2.0]), PlayHysteresis([2.0])
    a = [h1([x])[0] for x in up]
    b = [h2([x])[0] for x in slow]
    assert a[-1] == b[-1] == pytest.approx(1.0)  # output lags by half the band
    assert max(a) == max(b) == pytest.approx(9.0)
    with pytest.raises(softarm.ParameterError, match="width"):
        PlayHysteresis([-1.0])


def test_tracker_filters_at_ten_rad_per_second() -> None:
    tr = PoseTracker(np.random.default_rng(0), position_noise=0.0, angle_noise=0.0)
    tr.measure(np.eye(4), 0.0)
    step = np.eye(4)
    step[0, 3] = 1.0
    out = tr.measure(step, 0.1)
    assert out[0, 3] == pytest.approx(1 - math.exp(-1.0))
    noisy = PoseTracker(np.random.default_rng(0))
    m = noisy.measure(np.eye(4), 0.0)
    np.testing.assert_allclose(m[:3, :3] @ m[:3, :3].T, np.eye(3), atol=1e-12)


def test_bad_inputs() -> None:
    plant = SimulatedArm(seed=0)
    with pytest.raises(softarm.ShapeError, match="q"):
        plant.apply(np.zeros(8), 0.05)
    with pytest.raises(softarm.ParameterError, match="dt"):
        plant.apply(Q, 0.0)
    with pytest.raises(softarm.ParameterError, match="hysteresis_psi"):
        PlantConfig(hysteresis_psi=-1.0)
