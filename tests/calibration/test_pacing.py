"""The calibration's holds are paced for the plant: a slow, hysteretic plant is fitted
as well as the quick one (the fit otherwise absorbs an unsettled arm as geometry)."""

from __future__ import annotations

import math

import pytest

from softarm import SoftArm
from softarm.calibration.collect import DEFAULT_APPROACH_M, paced_for, settle_time
from softarm.calibration.sim import build_plant, calibrate_plant
from softarm.errors import ParameterError
from softarm.sim.arm import PlantConfig
from softarm.units import METRES_PER_PSI


def test_pacing_scales_with_the_lag_and_the_play() -> None:
    assert settle_time(0.18) == 1.0  # the quick rig keeps its 1 s
    assert settle_time(0.9) == pytest.approx(4.5)  # five time constants
    pace = paced_for(0.9, 5.0 * METRES_PER_PSI)
    assert pace["settle"] == pytest.approx(4.5)
    assert pace["approach"] == pytest.approx(2 * 5.0 * METRES_PER_PSI)  # through the band
    assert pace["approach_hold"] == pytest.approx(2.7)
    assert paced_for(0.18)["approach"] == DEFAULT_APPROACH_M


@pytest.mark.parametrize("bad", [-1.0, math.nan, math.inf])
def test_pacing_rejects_a_bad_lag_or_play(bad: float) -> None:
    with pytest.raises(ParameterError, match="lag_s"):
        settle_time(bad)
    with pytest.raises(ParameterError, match="play_m"):
        paced_for(0.1, bad)


def test_a_slow_hysteretic_plant_is_fitted_within_half_a_millimetre() -> None:
    # 0.8 s regulators and 5 psi of play (2.4 mm of elongation); with the quick rig's
    # pacing (1 s holds, a 2 mm dip) this plant fitted to a 20 mm median residual.
    config = PlantConfig(pressure_tau=0.8, hysteresis_psi=5.0)
    nominal = SoftArm.blackberry()
    plant = build_plant(nominal, config, 1504)
    cal, _, _ = calibrate_plant(plant, config, nominal, n_poses=40, seed=504)
    assert cal.converged
    assert cal.fit.position_median_mm < 0.5
    assert cal.fit.orientation_median_deg < 0.3
