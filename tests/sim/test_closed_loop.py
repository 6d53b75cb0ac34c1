"""Closed loop on the simulated plant: convergence from random starts to reachable
targets, commands never outside the limits, and the experiments' failure modes."""

from __future__ import annotations

import json
import math

import numpy as np

import softarm
from softarm._core import Gains
from softarm.experiments import hybrid, lag, position
from softarm.experiments.common import CONTROL_PERIOD, bush_pressures, closed_loop
from softarm.sim import SimulatedArm
from softarm.sim.arm import PlantConfig


def test_hybrid_converges_from_random_starts() -> None:
    plant = SimulatedArm(seed=7)
    rng = np.random.default_rng(7)
    # The plant's lag declared: regulators (80 ms) + the tracker's 10 rad/s filter.
    gains = softarm.Gains.for_lag(plant.config.pressure_tau + 0.1, CONTROL_PERIOD)
    res = softarm.Resolver(plant.model, "hybrid", gains)
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


def test_default_gains_converge_on_a_plant_lagging_20_periods() -> None:
    """Issue 9 item 3: DEFAULT settings, closed on the measured pose of a plant that is not
    the model, whose regulators lag 20 control periods behind a play hysteresis of 0.5 mm
    of elongation: every target reached within 1 mm and 1 deg and held (no limit cycle),
    never a command outside the limits. Today's gain (no lag bound) limit-cycles there."""
    res = lag.measure(
        taus=(1.0,), targets=3, seed=11, duration=60.0, controllers=("default", "today")
    )
    for r in res[(1.0, "default")]:
        assert r.reached, r
        assert r.ripple_mm < 0.5 and r.outside == 0, r
    assert not all(r.reached for r in res[(1.0, "today")])


def test_a_known_lag_converges_faster_than_the_defaults() -> None:
    res = lag.measure(
        taus=(0.3,), targets=3, seed=12, duration=40.0,
        controllers=("default", "for_lag", "predictor"),
    )  # fmt: skip

    def settle(name: str) -> float:
        runs = res[(0.3, name)]
        assert all(r.outside == 0 for r in runs), runs
        return float(np.median([r.settle_s if r.reached else math.inf for r in runs]))

    assert all(r.reached for r in res[(0.3, "for_lag")]), res[(0.3, "for_lag")]
    assert settle("for_lag") < settle("default")
    assert settle("predictor") < settle("default")


def test_default_gains_converge_next_to_the_joint_limits_through_play() -> None:
    """Issue 9 item 3, the target that limit-cycled with the defaults: four actuators on
    their limits at the solution, so the free columns' reduced Jacobian is ill-conditioned
    (smallest singular value 0.013) and an undamped 1/sigma turns the plant's mismatch and
    the play into a ~1 mm limit cycle. The closed-loop damping (Gains.loop_damping)
    converges there; with the model's damping in closed loop it does not (the mechanism,
    docs/control.md section 3). Seed 7, plant 1005: the case the damping was chosen on."""
    cfg = PlantConfig(pressure_tau=0.08, hysteresis_psi=lag.HYSTERESIS_PSI)
    case = lag.cases(cfg, targets=5, seed=7)[4]
    assert case.plant_seed == 1005

    def run(gains: Gains | None) -> lag.Run:
        plant = SimulatedArm(config=cfg, seed=case.plant_seed)
        return lag.run_one("default", plant, case.target, case.q0, 60.0, gains=gains)

    damped = run(None)
    assert damped.reached and damped.ripple_mm < 0.3 and damped.outside == 0, damped
    undamped = run(Gains(loop_damping=0.02, loop_singular_threshold=0.05))
    assert not undamped.reached and undamped.ripple_mm > 0.8, undamped


def test_a_corner_of_the_joint_limits_is_told_apart_from_a_loop_failure() -> None:
    """The default loop's small gain settles, 18 cm off, in a corner of the joint limits
    (seven channels on a limit) that ``Resolver.solve``'s larger steps cross: the same
    gains closed on the exact model, lag-free, settle there too, so the lag experiment
    counts it as a trap of the controller's own path (``on_model`` False), not as a
    failure of the loop on the lagging plant. Seed 45, plant 7002 (diagnosed there)."""
    cfg = PlantConfig(pressure_tau=0.3, hysteresis_psi=lag.HYSTERESIS_PSI)
    case = lag.cases(cfg, targets=3, seed=45, plant_seed=7000)[2]
    assert case.plant_seed == 7002
    run = lag.run_one("default", SimulatedArm(config=cfg, seed=7002), case.target, case.q0, 30.0)
    assert not run.reached and not run.on_model and run.final_mm > 100.0, run
    quick = lag.run_one("today", SimulatedArm(config=cfg, seed=7002), case.target, case.q0, 30.0)
    assert quick.on_model, quick  # alpha = 0.3 crosses the corner on the model
