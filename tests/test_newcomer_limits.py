"""Limits and words agree (issue 39, item 5): --berries bounded by the parser to what a
bush holds, typos answered with the nearest option, the survey's pairs counted alike
in --help and the code, a grasp outside tolerance is a failing exit status, a tagless
world's berries are not called tags, the unripe fruit is in the summary, a simulated vent
does not sound like hardware, and a stop is logged as one."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest

import softarm
from harvest.fakes import make_rig
from softarm import cli
from softarm.commands import harvest
from softarm.harvest import BerryTarget, HarvestLog
from softarm.harvest.control.survey import SurveySettings
from softarm.harvest.machine.states import HarvestState
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.runs.policy import run_targets
from softarm.sim import bush


def _error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit) as exit_:
        cli.main(argv)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    return err


@pytest.mark.parametrize("command", [["harvest", "--sim"], ["demo"]])
def test_the_parser_refuses_more_berries_than_a_bush_holds(
    command: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    n = bush.MAX_BERRIES + 1
    err = _error([*command, "--berries", str(n)], capsys)
    assert "--berries" in err and f"[1, {bush.MAX_BERRIES}]" in err
    assert harvest.MAX_BERRIES == bush.MAX_BERRIES


def test_an_unknown_keyword_names_simulate_harvest_and_the_nearest_option() -> None:
    with pytest.raises(TypeError, match=r"simulate_harvest\(\).*'wrold'.*'world'"):
        softarm.simulate_harvest(1, wrold="bush")


@pytest.mark.parametrize(
    ("argv", "hint"),
    [
        (["--verison"], "did you mean --version?"),
        (["harvest", "--sim", "--berry", "3"], "did you mean --berries?"),
        (["harvset", "--sim"], "did you mean 'harvest'?"),
    ],
)
def test_a_typo_gets_the_nearest_option(
    argv: list[str], hint: str, capsys: pytest.CaptureFixture[str]
) -> None:
    err = _error(argv, capsys)
    assert hint in err and "required: COMMAND" not in err


def test_help_counts_the_survey_pairs_the_code_flies(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        cli.main(["harvest", "--help"])
    words = {2: "two", 3: "three", 4: "four"}
    text = " ".join(capsys.readouterr().out.split())
    assert f"{words[SurveySettings().pairs]} pairs of views" in text


def _harvested(error_mm: float) -> BerryResult:
    result = BerryResult(0, harvested=True, true_position_error_mm=error_mm)
    result.true_orientation_error_deg = 0.1
    return result


def test_a_grasp_outside_tolerance_fails_the_run() -> None:
    tol = harvest.Tolerance()
    inside = HarvestReport([_harvested(0.5 * tol.position_mm)])
    off = HarvestReport([_harvested(2.0 * tol.position_mm)])
    assert not harvest.off_tolerance(inside, None) and harvest.off_tolerance(off, None)


def test_help_says_a_grasp_outside_tolerance_exits_1(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        cli.main(["harvest", "--help"])
    assert "1 some berry faulted or was harvested OUTSIDE TOLERANCE" in " ".join(
        capsys.readouterr().out.split()
    )


def test_the_sim_run_exits_1_when_a_grasp_is_outside_tolerance(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    tol = harvest.Tolerance()
    result = _harvested(2.0 * tol.position_mm)
    result.final_state = HarvestState.DONE
    monkeypatch.setattr(harvest, "_harvest", lambda rig, n, quiet: HarvestReport([result]))
    assert harvest.run_sim(1, 0, None, None, None, quiet=True) == 1
    assert "OUTSIDE TOLERANCE" in capsys.readouterr().out


def test_a_tagless_world_names_berries_by_their_map_number() -> None:
    result = BerryResult(0)
    assert "(map #0)" in harvest.line(0, 1, result, 0.0, tagged=False)
    assert "tag 0" not in harvest.line(0, 1, result, 0.0, tagged=False)
    assert "(tag 0)" in harvest.line(0, 1, result, 0.0)


def test_the_summary_mentions_the_unripe_fruit_left() -> None:
    d = HarvestReport([_harvested(0.1)]).to_dict()
    d.update(ripe_in_reach=1, ripe_harvested=1, unripe_left=1)
    assert "1/1 ripe berries picked, 1 unripe berry left on the bush" in harvest.summary(d)


def test_a_simulated_vent_does_not_sound_like_hardware(caplog: pytest.LogCaptureFixture) -> None:
    from softarm.hardware.safety import SafePressureBank
    from softarm.hardware.simulated import IdealPlant, SimulatedPressureBank

    plant = IdealPlant(9)
    for simulated, words in ((True, "simulated arm vented"), (False, "venting all 9 channels")):
        bank = SafePressureBank(
            SimulatedPressureBank(plant, 9), 30.0, 10.0, 1.0, lambda: 0.0,
            watchdog_thread=False, simulated=simulated,
        )  # fmt: skip
        caplog.clear()
        with caplog.at_level(logging.WARNING):
            bank.vent("unreachable")
        assert f"{words}: unreachable" in caplog.text


def test_a_stop_is_logged_as_interrupted_not_as_a_crash(tmp_path: Path) -> None:
    rig = make_rig(HarvestLog(tmp_path / "run.jsonl"))

    def stop(time: float) -> np.ndarray:
        raise KeyboardInterrupt

    rig.tracker.track = stop  # type: ignore[method-assign]
    with pytest.raises(KeyboardInterrupt):
        run_targets(rig.machine.run_berry, [BerryTarget(1)], rig.machine.log)
    kinds = [r["kind"] for r in rig.machine.log.records]
    assert "crash" not in kinds and kinds[-1] == "interrupted"
    assert rig.vented()
