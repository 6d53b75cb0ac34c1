"""``[harvest] play_skip``: fine positioning's command put at the play band's edge once it
has crept one way through the band for ``periods`` periods
(:class:`~softarm.harvest.machine.stages.play_skip.PlaySkip`): never before, never on a
command that turns back or lies outside the band, and never past what the creep would
reach (the plant's own play law moves the output by the loop's step alone); in a loop
through a lagging regulator and a play band it reaches the goal in a fraction of the
creep's time without overshoot; a bad value is one typed error naming the key."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.harvest import simulate
from softarm.harvest.control.plant_model import MeasurementModel
from softarm.harvest.machine.stages.play_skip import PlaySkip
from softarm.harvest_config import HarvestConfig
from softarm.sim.hysteresis import PlayHysteresis
from softarm.sim.plant_file import load_plant_file

SLOW_PLANT = Path(__file__).parents[2] / "examples" / "plants" / "slow_arm.toml"
W = 0.0024  # a 5 psi band, in elongation (m)
BAND = (np.zeros(2), np.full(2, W))  # the play output at 0 on both channels


def test_a_command_creeping_one_way_jumps_to_the_edge_after_its_periods() -> None:
    skip, q = PlaySkip(3), np.zeros(2)
    for _ in range(2):  # channel 0 creeps up, channel 1 stays put
        q_next = q + np.array([1e-5, 0.0])
        moved, channels = skip.step(q, q_next, BAND)
        assert channels == [] and np.array_equal(moved, q_next)
        q = moved
    moved, channels = skip.step(q, q + np.array([1e-5, 0.0]), BAND)
    assert channels == [0]
    assert moved[0] == pytest.approx(W / 2 + 1e-5) and moved[1] == 0.0


def test_a_command_that_turns_back_or_leaves_the_band_never_jumps() -> None:
    skip, q = PlaySkip(3), np.zeros(2)
    for k in range(20):  # channel 0 dithers about its place; channel 1 is beyond the band
        q_next = np.array([(-1) ** k * 1e-5, W])
        _, channels = skip.step(q, q_next, BAND)
        assert channels == []
        q = q_next


def test_without_a_play_model_nothing_changes() -> None:
    q_next = np.array([1e-5, 2e-5])
    for _ in range(5):
        moved, channels = PlaySkip(1).step(np.zeros(2), q_next, None)
        assert channels == [] and moved is q_next


@pytest.mark.parametrize("way", [1.0, -1.0])
def test_the_jump_moves_the_plants_play_output_by_the_loops_step_only(way: float) -> None:
    # Under the plant's own law, a command at the band's edge moves nothing; the jump
    # adds the loop's own step beyond it, which the output then follows, no more.
    plant = PlayHysteresis(np.full(2, W))
    skip, q = PlaySkip(1), np.zeros(2)
    step = way * np.array([2e-5, 0.0])
    moved, channels = skip.step(q, q + step, (plant.output.copy(), plant.width))
    assert channels == [0]
    assert plant(moved) == pytest.approx(step)


def _creep(skip: PlaySkip | None, tau: float = 0.8, period: float = 0.05) -> tuple[int, float]:
    """A channel that reversed: its output held at 0 with the command at the band's upper
    edge, the goal 0.5 mm below. An integral loop on the measured output (gain 0.05 a
    period), the command through a first-order regulator (``tau``) and the play. Returns
    the periods until the output is within 0.05 mm of the goal and the largest overshoot
    past it (m)."""
    plant = MeasurementModel(1, tau, period, play_m=W)
    plant.advance(np.full(1, W / 2))  # settle the regulator on the edge, output at 0
    for _ in range(200):
        plant.advance(np.full(1, W / 2))
    goal, q = -5e-4, np.full(1, W / 2)
    output, overshoot = plant.play_band()[0], 0.0
    for k in range(2000):
        q_next = q + 0.05 * (goal - output)
        if skip is not None:
            q_next, _ = skip.step(q, q_next, plant.play_band())
        q = q_next
        plant.advance(q)
        output = plant.play_band()[0]
        overshoot = max(overshoot, float(goal - output[0]))
        if abs(float(output[0]) - goal) < 5e-5:
            return k + 1, overshoot
    raise AssertionError("the loop did not reach its goal")


def test_a_loop_through_the_play_reaches_its_goal_sooner_without_overshoot() -> None:
    creep, creep_over = _creep(None)
    skipped, skip_over = _creep(PlaySkip(5))
    assert skipped < creep / 2
    assert skip_over <= creep_over + 1e-9


@pytest.mark.parametrize("value", [-1, 2.5, True, "5"])
def test_a_bad_play_skip_is_a_typed_error_naming_it(value: object) -> None:
    with pytest.raises(ParameterError, match="play_skip"):
        HarvestConfig(play_skip=value)  # type: ignore[arg-type]


def _slow_berry(tmp_path: Path, periods: int) -> tuple[float, set[str]]:
    """The first berry of bush 1531 on the slow plant, placed at the 5 cm standoff (a
    channel that reversed on the way in creeps through the 5 psi band in fine
    positioning; from the nearer standoff it does not): its time (s) and the states
    of the periods in which a channel was put at the band's edge."""
    log = tmp_path / f"run{periods}.jsonl"
    config = HarvestConfig(play_skip=periods, near_standoff=0.0)
    plant = load_plant_file(SLOW_PLANT)
    report = simulate(1, 1531, log=log, plant=plant, config=config, marker_body="frustum")
    assert report.berries[0].harvested
    rows = [json.loads(line) for line in log.read_text().splitlines()]
    state = {r["t"]: r["state"] for r in rows if r["kind"] == "step"}
    return report.berries[0].duration_s, {state[r["t"]] for r in rows if r["kind"] == "play_skip"}


def test_on_the_slow_plant_only_fine_positioning_skips_and_the_berry_is_quicker(
    tmp_path: Path,
) -> None:
    creep, none = _slow_berry(tmp_path, 0)
    skipped, states = _slow_berry(tmp_path, 5)
    assert none == set() and states == {"fine_positioning"}
    assert skipped < creep - 1.0
