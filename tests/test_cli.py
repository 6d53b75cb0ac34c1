"""The command line's contract with its user: every usage error is one line naming the
option, exit status 2, before any work starts and without creating anything; help shows
the defaults; --version, python -m softarm, --json output, completion scripts."""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm import _core, cli
from softarm.commands._args import output_dir, output_file
from softarm.formatting import rounded


def run_cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """``softarm ARGV`` in process: (exit status, stdout, stderr)."""
    try:
        status = cli.main(argv)
    except SystemExit as exc:
        status = int(exc.code or 0)
    out, err = capsys.readouterr()
    return status, out, err


BAD = [
    (["harvest", "--sim", "--seed", "-5"], "--seed"),
    (["harvest", "--sim", "--seed", "five"], "--seed"),
    (["harvest", "--sim", "--berries", "0"], "--berries"),
    (["harvest", "--sim", "--report", "{tmp}"], "--report"),
    (["harvest", "--sim", "--log", "/proc/nope/log.jsonl"], "--log"),
    (["harvest", "--sim", "--plot", "{tmp}/run.unknown"], "--plot"),
    (["harvest", "--sim", "--plot", "{tmp}"], "--plot"),
    (["harvest", "--sim", "--report", "/proc/nope/r.json"], "--report"),
    (["harvest", "--config", "{tmp}/absent.toml"], "--config"),
    (["harvest", "--config", "{tmp}"], "--config"),
    (["demo", "--berries", "0", "--out", "{tmp}/demo"], "--berries"),
    (["demo", "--out", "/proc/nope"], "--out"),
    (["experiment", "all", "--out", "/proc/nope"], "--out"),
    (["experiment", "position", "--report", "{tmp}"], "--report"),
    (["plan", "--repeats", "-1"], "--repeats"),
    (["plan", "--plot", "/proc/nope/x.png"], "--plot"),
    (["bench", "--seconds", "1e308"], "--seconds"),
    (["bench", "--seconds", "nan"], "--seconds"),
]


@pytest.mark.parametrize(("argv", "option"), BAD, ids=[" ".join(a) for a, _ in BAD])
def test_usage_errors_are_one_line_naming_the_option(
    argv: list[str], option: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    before = sorted(tmp_path.rglob("*"))
    status, _, err = run_cli(argv, capsys)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert f"argument {option}" in lines[0] and "error" in lines[0]
    assert "Traceback" not in err and "n_berries" not in err
    assert sorted(tmp_path.rglob("*")) == before  # nothing created


@pytest.mark.parametrize(
    ("content", "why"),
    [(b"\xef\xbb\xbf[arm]\n", "byte-order mark"), (b"[arm]\nname = '\xff\xfe'\n", "not UTF-8")],
)
def test_config_encoding_errors_name_the_option(
    content: bytes, why: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "hw.toml"
    path.write_bytes(content)
    status, _, err = run_cli(["harvest", "--config", str(path)], capsys)
    assert status == 2
    assert err.count("\n") == 1 and "argument --config" in err and why in err


def test_plot_needs_the_simulator(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from softarm.commands.config import template

    config = tmp_path / "hw.toml"
    config.write_text(template())
    argv = ["harvest", "--config", str(config), "--plot", str(tmp_path / "p.png")]
    status, _, err = run_cli(argv, capsys)
    assert status == 2 and err.count("\n") == 1 and "argument --plot" in err


def test_output_checks_create_nothing(tmp_path: Path) -> None:
    assert output_file(str(tmp_path / "r.json")) == tmp_path / "r.json"
    assert output_dir(str(tmp_path / "a" / "b")) == tmp_path / "a" / "b"
    assert list(tmp_path.iterdir()) == []  # the writability probe leaves nothing behind
    (tmp_path / "f").write_text("")
    with pytest.raises(argparse.ArgumentTypeError, match="not a directory"):
        output_dir(str(tmp_path / "f"))
    with pytest.raises(argparse.ArgumentTypeError, match="is a file"):
        output_dir(str(tmp_path / "f" / "sub"))


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run_cli(["--version"], capsys)
    assert status == 0
    assert out.strip() == f"softarm {softarm.__version__}"
    from importlib.metadata import version

    assert softarm.__version__ == version("softarm")


def test_python_dash_m() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "softarm", "--version"], capture_output=True, text=True, check=False
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == f"softarm {softarm.__version__}"


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    found: dict[str, argparse.ArgumentParser] = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                found[f"{parser.prog} {name}"] = sub
                found.update(_subparsers(sub))
    return found


def test_every_help_shows_the_defaults() -> None:
    subs = _subparsers(cli.build_parser())
    assert {"softarm harvest", "softarm demo", "softarm config init"} <= set(subs)
    for prog, parser in subs.items():
        text = " ".join(parser.format_help().split())
        for action in parser._actions:
            if not action.option_strings or any(
                action.default is nothing for nothing in (None, False, argparse.SUPPRESS)
            ):
                continue
            shown = f"(default: {action.default})"
            assert shown in text, f"{prog} {action.option_strings[0]}: {shown} not in help"


def test_a_command_that_cannot_import_is_listed_and_says_why(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(cli.COMMANDS, "broken", "softarm.commands.does_not_exist")
    status, _, err = run_cli(["broken", "--anything"], capsys)
    assert status == 2 and "unavailable" in err
    status, out, _ = run_cli(["plan", "--help"], capsys)  # the others still work
    assert status == 0 and "--repeats" in out


def test_every_registered_command_imports() -> None:
    import importlib

    for module in cli.COMMANDS.values():
        importlib.import_module(module)


def test_plan_json(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    from softarm.planning import scenarios

    planned: list[scenarios.Result] = []
    original = scenarios.compare

    def compare(name: str, repeats: int = 20) -> list[scenarios.Result]:
        planned.extend(original(name, repeats))
        return planned

    monkeypatch.setattr(scenarios, "compare", compare)
    status, out, _ = run_cli(["plan", "--scenario", "line", "--repeats", "1", "--json"], capsys)
    doc = json.loads(out)
    assert doc["scenario"] == "line" and len(doc["results"]) == 5
    proposed = doc["results"][0]
    assert proposed["method"] == "proposed"
    # The proposed plan reached the goal: judged on the geometry of the path it planned,
    # not on its own flag. The arm starts straight, its tip 2 m from the goal.
    line, plan = scenarios.load("line"), planned[0].plan
    tip = lambda q: line.chain.forward(q)[:3, 3]  # noqa: E731
    assert np.linalg.norm(tip(plan.path[0]) - line.goal) > 1.0
    assert np.linalg.norm(tip(plan.path[-1]) - line.goal) <= 0.01  # the goal tolerance
    clearance = _core.path_clearance(line.chain, plan.path, list(line.curves), 8)
    assert clearance >= scenarios.COLLISION_DISTANCE
    assert proposed["reached"] and not proposed["collision"] and status == 0
    assert proposed["iterations"] == plan.iterations == len(plan.path) - 1
    assert proposed["min_clearance_m"] == pytest.approx(clearance, abs=1e-4)


def test_bench_json(capsys: pytest.CaptureFixture[str]) -> None:
    import platform

    status, out, _ = run_cli(["bench", "--seconds", "0.001", "--no-vision", "--json"], capsys)
    assert status == 0
    doc = json.loads(out)
    assert doc["python"] == platform.python_version()
    rows = doc["timings"]
    # Every operation timed, none of OpenCV's (--no-vision), each over at least the three
    # batches the median is taken of.
    assert [r["operation"] for r in rows] == [
        "SoftArm.forward",
        "SoftArm.jacobian",
        "SoftArm.forward_batch (10k poses)",
        "Resolver.step (hybrid, eq. 20)",
        "closest(arc chain, 6 curves)",
        "PotentialFieldPlanner.plan (sim 3)",
    ]
    assert all(r["median_s"] > 0 and r["calls"] >= 3 for r in rows)


def test_bench_times_operations_that_do_their_work() -> None:
    """What `bench` times gives the right answers: a timing of a call that fails or
    returns nothing would say nothing of the operation."""
    from softarm.commands.bench import _cases

    results = {name: fn() for name, fn in _cases(with_vision=True)}
    assert results["SoftArm.forward"].shape == (4, 4)
    assert results["SoftArm.jacobian"].shape == (6, 9)
    assert results["SoftArm.forward_batch (10k poses)"].shape == (10_000, 4, 4)
    step = results["Resolver.step (hybrid, eq. 20)"]
    assert step.q.shape == (9,) and np.all(np.isfinite(step.q))
    assert step.position_error > 0.0  # the goal is 3 mm per channel away
    assert len(results["closest(arc chain, 6 curves)"]) == 6
    assert results["PotentialFieldPlanner.plan (sim 3)"].reached
    assert results["MarkerCube.estimate_pose (1280x720)"] is not None


def test_rounded() -> None:
    assert rounded({"a": [0.1 + 0.2, 2.7499999999999982], "b": 3, "c": "x"}) == {
        "a": [0.3, 2.75],
        "b": 3,
        "c": "x",
    }
    assert rounded(float("inf")) == float("inf")


@pytest.mark.parametrize("shell", ["bash", "zsh"])
def test_completion_script(shell: str, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("shtab")
    status, out, _ = run_cli(["completion", shell], capsys)
    assert status == 0
    for word in ("harvest", "--berries", "experiment", "--json"):
        assert word in out


def test_bash_completion_loads(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("shtab")
    _, out, _ = run_cli(["completion", "bash"], capsys)
    script = tmp_path / "softarm.bash"
    script.write_text(out)
    proc = subprocess.run(
        ["bash", "-c", f"source {script} && complete -p softarm"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert "softarm" in proc.stdout


def test_config_init_then_harvest_reaches_the_hardware_in_one_attempt(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import re

    path = tmp_path / "hw.toml"
    assert run_cli(["config", "init", str(path)], capsys)[0] == 0
    status, _, err = run_cli(["config", "init", str(path)], capsys)
    assert status == 2 and "--force" in err  # never overwrites by accident
    # As written, the template is valid and says everything that is missing at once.
    status, out, _ = run_cli(["config", "check", str(path)], capsys)
    assert status == 1
    for key in ("T_C1_base", "T_C2_EE", "c1.matrix", "c2.matrix"):
        assert key in out
    status, _, err = run_cli(["harvest", "--config", str(path)], capsys)
    assert status == 2 and "T_C1_base" in err and "c2.matrix" in err
    # Calibrations filled in (the placeholders uncommented): the next stop is the hardware.
    text = path.read_text()
    path.write_text(re.sub(r"(?m)^# ((T_C1_base|T_C2_EE|matrix|distortion) = )", r"\1", text))
    status, out, _ = run_cli(["config", "check", str(path)], capsys)
    assert status == 0 and "ready" in out
    status, _, err = run_cli(["harvest", "--config", str(path)], capsys)
    assert status == 2
    assert "hardware not available" in err


def test_soft_arm_from_config(tmp_path: Path) -> None:
    from softarm.commands.config import template
    from softarm.config import default_config, load_config

    path = tmp_path / "hw.toml"
    path.write_text(template())
    q = [0.01, 0.0, 0.02, 0.03, 0.0, 0.01, 0.0, 0.02, 0.0]
    expected = softarm.SoftArm.blackberry().forward(q)
    for source in (path, str(path), load_config(path), default_config().arm):
        arm = softarm.SoftArm.from_config(source)
        assert isinstance(arm, softarm.SoftArm)
        assert arm.forward(q) == pytest.approx(expected, abs=1e-12)
    with pytest.raises(softarm.ConfigError, match="config must be"):
        softarm.SoftArm.from_config(42)  # type: ignore[arg-type]
    with pytest.raises(softarm.ConfigError):
        softarm.SoftArm.from_config(tmp_path / "absent.toml")


def test_package_surface() -> None:
    names = dir(softarm)
    for sub in ("vision", "hardware", "harvest", "sim", "planning", "config", "experiments"):
        assert sub in names
        assert getattr(softarm, sub).__name__ == f"softarm.{sub}"
    assert "Keyword-only constructor" in (softarm.Gains.__doc__ or "")
    assert "see the stub" not in (softarm.Gains.__doc__ or "")
    import pydoc

    assert "Constructor: Gains(" in pydoc.render_doc(softarm.Gains)


def test_a_normal_start_logs_no_warning(caplog: pytest.LogCaptureFixture) -> None:
    """The startup vent is routine (INFO); a vent for a reason stays a WARNING."""
    import logging

    from softarm.hardware import IdealPlant, SafePressureBank, SimulatedPressureBank

    with caplog.at_level(logging.INFO, logger="softarm"):
        bank = SafePressureBank(
            SimulatedPressureBank(IdealPlant(9), 9), 70.0, 100.0, 0.5, watchdog_thread=False
        )
        assert [r.levelno for r in caplog.records] == [logging.INFO]
        bank.vent("fault: test")
        assert caplog.records[-1].levelno == logging.WARNING
        bank.close()


def test_sim_harvest_lines_reports_and_quiet(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One berry: the per-berry line gives that berry's own simulated and wall time (not
    a running total); the report and log are written; --quiet keeps the summary only."""
    files = [str(tmp_path / n) for n in ("r.json", "l.jsonl", "p.png")]
    argv = ["harvest", "--sim", "--berries", "1", "--seed", "0"]
    argv += ["--report", files[0], "--log", files[1], "--plot", files[2]]
    status, out, err = run_cli(argv, capsys)
    assert status in (0, 1), err
    (berry_line,) = [line for line in out.splitlines() if line.startswith("berry 1/1")]
    assert re.search(r"took \d+\.\d s simulated, \d+\.\d s wall$", berry_line)
    assert "WARNING" not in err and "startup" not in err  # a normal start is not a warning
    report = json.loads(Path(files[0]).read_text())
    assert report["attempted"] == 1
    assert all(len(repr(v)) < 12 for v in report["berries"][0].values() if isinstance(v, float))
    assert Path(files[2]).stat().st_size > 0
    status, out, _ = run_cli([*argv[:6], "--quiet"], capsys)
    assert out.strip().startswith("harvested ")  # the summary line, nothing before it


@pytest.mark.parametrize(
    ("content", "why"),
    [(b"\xef\xbb\xbf[arm]\n", "byte-order mark"), (b"[arm]\nname = '\xff'\n", "not UTF-8")],
)
def test_load_config_encoding_errors_are_config_errors(
    content: bytes, why: str, tmp_path: Path
) -> None:
    """The Python API too: a ConfigError naming the file, not a UnicodeDecodeError."""
    from softarm.config import load_config

    path = tmp_path / "hw.toml"
    path.write_bytes(content)
    with pytest.raises(softarm.ConfigError, match=why):
        load_config(path)
