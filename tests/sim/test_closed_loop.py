"""Closed loop on the simulated plant: convergence from random starts to reachable
targets, commands never outside the limits, and the experiments' failure modes."""

from __future__ import annotations

import json
import math

import numpy as np

import softarm
from softarm.experiments import hybrid, position
from softarm.experiments.common import bush_pressures, closed_loop
from softarm.sim import SimulatedArm


def test_hybrid_converges_from_random_starts() -> None:
    plant = SimulatedArm(seed=7)
    rng = np.random.default_rng(7)
    res = softarm.Resolver(plant.model, "hybrid")
    lo, hi = plant.model.lower, plant.model.upper
    for p in bush_pressures(plant, rng, 6):
        target = plant.pose_at_pressure(p)
        q0 = rng.uniform(lo, hi)  # anywhere in the limits
        tr = closed_loop(res, plant, target, q0, 25.0)
        ep, eo = tr.final()
        assert ep < 1.5e-3 and eo < math.radians(1.0), (ep, eo)
        assert tr.infeasible == 0
        cmds = np.asarray(tr.command_psi) / 2100.0
        assert np.all(cmds >= lo - 1e-15) and np.all(cmds <= hi + 1e-15)


def test_position_experiment_counts_infeasible_conventional_commands(tmp_path) -> None:
    s = position.run(tmp_path, seed=0, quick=True)
    assert s["proposed_infeasible_commands"] == 0
    assert s["conventional_infeasible_commands"] > 0
    assert s["proposed_mm"]["mean"] < 1.0
    assert json.loads((tmp_path / "position.json").read_text())["set_points"] == 8
    assert (tmp_path / "position.csv").exists() and (tmp_path / "position.png").exists()


def test_hybrid_experiment_reaches_the_goal_and_conventional_fails(tmp_path) -> None:
    s = hybrid.run(tmp_path, seed=0, quick=True)
    assert s["with_limits"]["mm"]["mean"] < 1.0
    assert s["with_limits"]["deg"]["mean"] < 1.0
    assert s["with_limits"]["infeasible_commands"] == 0
    assert s["conventional"]["mm"]["mean"] > 5.0
    assert (tmp_path / "hybrid.png").exists()


def test_experiment_command_line(tmp_path, capsys) -> None:
    from softarm.cli import main

    report = tmp_path / "experiments.md"
    assert (
        main(["experiment", "schedule", "--quick", "--out", str(tmp_path), "--report", str(report)])
        == 0
    )
    assert "position_smooth" in capsys.readouterr().out
    assert "step (eq. 23–25)" in report.read_text()
