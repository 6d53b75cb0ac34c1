"""One trial outside Ray: a trial that raises becomes one error row; gains reach the
closed-loop resolver of the rig."""

from __future__ import annotations

import pytest

import softarm
from softarm.errors import ConfigError
from softarm.harvest.sim_rig import SimRigOptions, build_sim_rig
from softarm.sweep.gains_file import apply_gains
from softarm.sweep.spec import TrialSpec
from softarm.sweep.trial import BERRY_COLUMNS, run_trial_rows


def test_a_trial_that_raises_is_one_error_row() -> None:
    # The rig refuses the Cosserat plant model: the trial fails before harvesting.
    trial = TrialSpec(seed=0, plant={"model": "cosserat"}, berries=1, rig={}, gains={})
    (row,) = run_trial_rows(trial)
    assert row["error"] is not None and "cosserat" in row["error"]
    assert row["trial_id"] == trial.trial_id and row["model"] == "cosserat"
    assert row["harvested"] is None
    assert set(BERRY_COLUMNS) <= set(row)


def test_gains_replace_the_closed_loop_resolver_only() -> None:
    rig = build_sim_rig(SimRigOptions(n_berries=1, seed=0, joint_limit_gain=-1e-5))
    controller = rig.machine.servo.controller
    apply_gains(rig, {"hybrid_alpha": 0.11})
    assert controller.resolver.gains.hybrid_alpha == 0.11
    assert controller.resolver.gains.hybrid_gamma == -1e-5  # the rig's own setting is kept
    assert controller.resolver.arm.n_dofs == softarm.SoftArm.blackberry().n_dofs
    with pytest.raises(ConfigError, match="alpha: unknown gain"):
        apply_gains(rig, {"alpha": 0.1})
