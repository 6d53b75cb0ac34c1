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


def test_the_held_out_reference_is_settled_on_a_slow_plant() -> None:
    """``true_poses`` (the held-out truth of the fidelity experiments) holds each pose
    as long as the plant's lag needs: on 0.8 s regulators without play it equals the
    plant's static pose (closed form, ``pose_at_pressure``); the old fixed 1 s hold left
    the arm short of it."""
    import numpy as np

    from softarm.calibration.excitation import excitation_set
    from softarm.calibration.sim import true_poses

    config = PlantConfig(pressure_tau=0.8, hysteresis_psi=0.0)
    nominal = SoftArm.blackberry()
    commands = excitation_set(nominal, 4, seed=3)

    def worst_mm(settle: float | None) -> float:
        plant = build_plant(nominal, config, seed=1004)
        got = true_poses(plant, commands, config, settle=settle)
        static = build_plant(nominal, config, seed=1004)
        want = [static.sim.pose_at_pressure(c / METRES_PER_PSI) for c in commands]
        assert len(got) == len(want)
        return 1e3 * max(
            float(np.linalg.norm(g[:3, 3] - w[:3, 3])) for g, w in zip(got, want, strict=True)
        )

    assert worst_mm(None) < 0.1
    assert worst_mm(1.0) > 1.0


def test_a_fixed_hold_can_still_be_asked_for() -> None:
    """``settle`` overrides the paced hold (examples/fidelity.py's quicker rod runs)."""
    config = PlantConfig()
    nominal = SoftArm.blackberry()
    plant = build_plant(nominal, config, seed=1000)
    cal, c, p = calibrate_plant(plant, config, nominal, n_poses=24, seed=1, settle=0.6)
    assert c.shape == (24, 9) and p.shape == (24, 4, 4)
    assert cal.arm.n_dofs == 9
