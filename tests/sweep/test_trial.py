"""One trial outside Ray: a trial that raises becomes one error row; gains reach the
closed-loop resolver of the rig."""

from __future__ import annotations

from pathlib import Path

import pytest

import softarm
from softarm.errors import ConfigError
from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.rig import build_sim_rig
from softarm.sweep.spec import TrialSpec
from softarm.sweep.trial import BERRY_COLUMNS, run_trial_rows


def test_a_trial_that_raises_is_one_error_row() -> None:
    # A plant the spec parser would refuse, sent anyway: the trial fails before harvesting.
    trial = TrialSpec(seed=0, plant={"pressure_tau": -1.0}, berries=1, rig={}, gains={})
    (row,) = run_trial_rows(trial)
    assert row["error"] is not None and "ParameterError" in row["error"], row["error"]
    assert "pressure_tau" in row["error"]
    assert row["trial_id"] == trial.trial_id and row["pressure_tau"] == -1.0
    assert row["harvested"] is None
    assert set(BERRY_COLUMNS) <= set(row)


def test_gains_reach_every_controller_resolver() -> None:
    options = SimRigOptions(
        n_berries=1, seed=0, joint_limit_gain=-1e-5, gains={"hybrid_alpha": 0.11}
    )
    controller = build_sim_rig(options).machine.servo.controller
    for resolver in (controller.resolver, controller.transport):
        assert resolver.gains.hybrid_alpha == 0.11
        assert resolver.gains.hybrid_gamma == -1e-5  # the rig's own setting is kept
        assert resolver.arm.n_dofs == softarm.SoftArm.blackberry().n_dofs
    with pytest.raises(ConfigError, match="alpha: unknown gain"):
        build_sim_rig(SimRigOptions(n_berries=1, seed=0, gains={"alpha": 0.1}))


def test_harvest_gains_option_checks_the_file_first(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from softarm.cli import main

    bad = tmp_path / "gains.toml"
    bad.write_text("[gains]\nhybrid_alpha = 9.0\n")
    assert main(["harvest", "--sim", "--berries", "1", "--gains", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "[gains] hybrid_alpha" in err and err.count("\n") == 1


def test_a_trial_row_carries_the_bushs_rate() -> None:
    """Each berry's row repeats its bush's rate (softarm.harvest.records.rate) and its
    simulated time."""
    trial = TrialSpec(seed=90040, plant={}, berries=1, rig={}, gains={})
    rows = run_trial_rows(trial, single_threaded=False)
    assert rows and all(r["error"] is None for r in rows), rows
    (row,) = rows
    assert row["sim_s"] > 0
    assert row["berries_per_hour"] == pytest.approx(3600 * int(row["harvested"]) / row["sim_s"])
