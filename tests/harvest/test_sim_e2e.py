"""End to end on the simulator: rendered images → vision → fusion → resolver → safety
layer → simulated arm. One berry each, to stay short."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softarm.cli import main
from softarm.harvest import FaultReason, HarvestState, read_log
from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.rig import build_sim_rig
from softarm.harvest_config import HarvestConfig
from softarm.sim.arm import PlantConfig

pytestmark = pytest.mark.slow


def test_one_berry_is_harvested_within_a_millimetre(tmp_path) -> None:
    rig = build_sim_rig(SimRigOptions(n_berries=1, seed=0, log_path=tmp_path / "log.jsonl"))
    report = rig.run()
    (berry,) = report.berries
    assert berry.harvested and berry.final_state is HarvestState.DONE
    assert berry.true_position_error_mm is not None and berry.true_position_error_mm <= 1.0
    assert berry.cameras["eye_in_hand"] > 0 and berry.cameras["eye_to_hand"] > 0
    assert rig.gripper.delivered == [rig.bush.berries[0].tag_id]
    assert report.extra["branch_contact_steps"] == 0
    kinds = [r["kind"] for r in read_log(tmp_path / "log.jsonl")]
    assert kinds.count("transition") == 6 and "plan" in kinds


def test_berry_hidden_by_leaves_is_marker_lost_and_vented() -> None:
    # Hidden from 0.3 s on: lost during the placement, far from the berry.
    opts = SimRigOptions(n_berries=1, seed=0, hidden=lambda t: t > 0.3)
    rig = build_sim_rig(opts)
    result = rig.machine.run_berry(_target(rig))
    assert result.fault is FaultReason.MARKER_LOST
    assert "marker_lost" in rig.bank.vent_log[-1].reason
    assert np.all(rig.bank.last_sent == 0.0)  # every channel at 0 psi


def test_a_berry_lost_in_fine_positioning_inside_the_grippers_reach_is_grasped() -> None:
    # Hidden from 0.5 s on (early in placement): the held fix carries fine positioning
    # to about 1 mm of the berry, where it is lost; the arm held still, so it grasps there
    # (III-D's ±1 cm).
    rig = build_sim_rig(SimRigOptions(n_berries=1, seed=0, hidden=lambda t: t > 0.5))
    result = rig.machine.run_berry(_target(rig))
    assert result.harvested and result.fault is None
    assert result.position_error_mm is not None and result.position_error_mm <= 10.0
    (lost,) = [r for r in rig.machine.log.records if r["kind"] == "lost_grasp"]
    assert lost["error"] <= 0.01 and "not seen" in lost["detail"]


def test_a_berry_lost_farther_than_the_grippers_reach_stays_marker_lost() -> None:
    # The same loss with a gripper that reaches only 0.7 mm: the last error is beyond.
    config = HarvestConfig(grasp_workspace=0.0007, stall_progress=0.001)
    opts = SimRigOptions(n_berries=1, seed=0, hidden=lambda t: t > 0.5, config=config)
    rig = build_sim_rig(opts)
    result = rig.machine.run_berry(_target(rig))
    assert result.fault is FaultReason.MARKER_LOST and not result.harvested
    assert not [r for r in rig.machine.log.records if r["kind"] == "lost_grasp"]


def _target(rig):
    from softarm.harvest import BerryTarget

    return BerryTarget(rig.bush.berries[0].tag_id)


def test_cli_sim_writes_the_report(tmp_path, capsys) -> None:
    out = tmp_path / "run.json"
    assert main(["harvest", "--sim", "--berries", "1", "--seed", "0", "--report", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["success_rate"] == 1.0 and len(data["berries"]) == 1
    assert "berry 1/1" in capsys.readouterr().out


def test_slow_plant_hands_the_plan_over_to_the_loop_on_the_berry(tmp_path) -> None:
    # 1 s regulators and 5 psi of play: the plan's lag-bounded correction would take
    # seconds to remove the model's error; once the lag model has the arm at the plan's
    # end, the loop on the berry (predicted, full gain) takes over instead of stalling.
    _, report, kinds = _on_a_slow_plant(tmp_path, n_berries=1, seed=0)
    (berry,) = report.berries
    assert berry.harvested and berry.true_position_error_mm is not None
    assert berry.true_position_error_mm <= 1.0
    assert "waypoint_handover" in kinds and "waypoint_stalled" not in kinds


def test_a_lagging_arm_does_not_cut_across_a_cane_on_its_way_to_the_first_berry(tmp_path) -> None:
    # Seed 504 on a 1 s / 5 psi plant, not calibrated: the plan's first move used to
    # touch a cane (6 steps, 3.9 mm deep). Each command was clear on the model, but the
    # correction piled up while the arm trailed a whole lag behind, and the arm cut
    # across from where it was to where the command had gone. The transport holds a
    # command whose way from the lag model's arm is not clear (`transport_held`: it
    # held two and kept 7.0 mm clear here), and its correction compares the measured
    # pose with the plan's point where the arm is, not the plan's point ahead of it, so
    # that the lag no longer piles up as a correction: no command held, 14 mm clear.
    # A reproduction on the diagnosis seed it was traced on: the mechanism, not the
    # accuracy (that is judged on a fresh bush below).
    rig, _, _ = _on_a_slow_plant(tmp_path, n_berries=8, seed=504)
    assert rig.watch.contacts == 0
    assert rig.watch.min_gap >= 0.01  # the transport's margin, on the true arm


def test_a_lagging_arm_harvests_a_fresh_bush_without_touching_a_cane(tmp_path) -> None:
    # The same 1 s / 5 psi plant, uncalibrated, on a bush from the seeds reserved for CI
    # (docs/architecture.md, "Seeds"): no cane touched, at most one berry of 8 missed.
    rig, report, _ = _on_a_slow_plant(tmp_path, n_berries=8, seed=90020)
    assert rig.watch.contacts == 0 and rig.watch.min_gap > 0.0
    assert report.success_rate >= 7 / 8


def test_the_way_home_keeps_the_plans_waypoint_where_the_straight_way_is_not_clear() -> None:
    # Seed 1432's first berry (a diagnosis seed): the back-out left the arm at the
    # pre-grasp pose a few mm of elongation off the plan's q, and from there the straight
    # way home ran into a cane within one step (model gap 45 mm -> 1 mm). The way home
    # then held its first command for the whole home timeout (10 s) and ramped home open
    # loop, unchecked, touching the cane. The way home now passes the plan's q, whose way
    # home the plan checked.
    rig = build_sim_rig(SimRigOptions(n_berries=6, seed=1432))
    result = rig.machine.run_berry(_target(rig))
    assert result.harvested
    kinds = [r["kind"] for r in rig.machine.log.records]
    assert "return_open_loop" not in kinds and "transport_held" not in kinds
    assert rig.watch.contacts == 0


def _on_a_slow_plant(tmp_path, n_berries: int, seed: int):  # type: ignore[no-untyped-def]
    """Harvest a bush on a 1 s / 5 psi plant (the nominal model, not calibrated):
    ``(rig, report, the kinds of the log's records)``."""
    options = SimRigOptions(
        n_berries=n_berries,
        seed=seed,
        log_path=tmp_path / "log.jsonl",
        plant=PlantConfig(pressure_tau=1.0, hysteresis_psi=5.0),
    )
    rig = build_sim_rig(options)
    report = rig.run()
    return rig, report, [r["kind"] for r in read_log(tmp_path / "log.jsonl")]
