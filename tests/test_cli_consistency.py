"""One command line (issue 25 item 6): every command takes -q/--quiet, help text carries
no reST markup and says a default once, and a missing extra for --record is caught before
any work starts."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from softarm import cli

QUIET_EVERYWHERE = ("harvest", "identify", "calibrate", "sweep", "tune", "experiment")


def _parsers() -> dict[str, argparse.ArgumentParser]:
    """Every parser by its prog, subcommands of subcommands included."""
    found: dict[str, argparse.ArgumentParser] = {}
    todo = [cli.build_parser()]
    while todo:
        p = todo.pop()
        found[p.prog] = p
        for action in p._actions:
            if isinstance(action, argparse._SubParsersAction):
                todo.extend(action.choices.values())
    return found


@pytest.mark.parametrize("command", QUIET_EVERYWHERE)
def test_every_command_takes_q(command: str) -> None:
    parser = _parsers()[f"softarm {command}"]
    options = {o for a in parser._actions for o in a.option_strings}
    assert {"-q", "--quiet"} <= options, command


def test_help_has_no_rest_markup_and_says_each_default_once() -> None:
    for prog, parser in _parsers().items():
        text = parser.format_help()
        assert "``" not in text, prog
        assert not re.search(r":(class|func|mod|meth|attr|ref):`", text), prog
        for line in text.splitlines():
            assert len(re.findall(r"\(default\b", line, re.IGNORECASE)) <= 1, (prog, line)


@pytest.mark.parametrize(
    ("command", "default"), [("identify", "id.json"), ("calibrate", "model.toml")]
)
def test_identify_and_calibrate_both_default_out(
    command: str, default: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    args = cli.build_parser().parse_args([command, "--sim"])
    assert args.out == Path(default)
    assert f"(default: {default})" in _parsers()[f"softarm {command}"].format_help()


def test_a_default_out_is_checked_before_any_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "id.json").mkdir()  # the default output is a directory here
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:
        cli.build_parser().parse_args(["identify", "--sim"])
    assert exc.value.code == 2
    assert "argument --out: 'id.json' is a directory" in capsys.readouterr().err


def test_help_that_names_its_default_gets_no_second_one() -> None:
    from softarm.commands._args import Parser

    p = Parser(prog="x")
    p.add_argument("--poses", type=int, default=80, help="excitation poses (default 80)")
    p.add_argument("--n", type=int, default=3, help="count")
    text = p.format_help()
    assert "(default 80)" in text and "(default: 80)" not in text
    assert "(default: 3)" in text


def test_record_without_the_viz_extra_fails_before_any_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "rerun", None)  # import rerun raises ImportError
    log = tmp_path / "run.jsonl"
    argv = ["harvest", "--sim", "--berries", "1", "--log", str(log)]
    status = cli.main([*argv, "--record", str(tmp_path / "run.rrd")])
    out, err = capsys.readouterr()
    assert status == 2
    assert "viz" in err and len(err.strip().splitlines()) == 1
    assert "simulated harvest" not in out and out == ""
    assert not log.exists() and not (tmp_path / "run.rrd").exists()
    from softarm.commands.harvest import run_sim

    with pytest.raises(Exception, match="viz"):  # demo's path: the same check first
        run_sim(1, 0, log, None, None, quiet=True, record=tmp_path / "run.rrd")
    assert not log.exists() and capsys.readouterr().out == ""


def test_experiment_stdout_is_its_json_alone(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    status = cli.main(["experiment", "position", "--quick", "--out", str(tmp_path / "x")])
    out, err = capsys.readouterr()
    assert status == 0
    assert "position" in json.loads(out)  # nothing before (or after) the JSON
    assert "position: done in" in err
