"""The controller's measurement-chain model against the simulated plant's own parts."""

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.harvest.plant_model import MeasurementModel
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
