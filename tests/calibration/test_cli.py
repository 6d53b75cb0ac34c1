"""``softarm calibrate --sim``: drives the simulated plant, writes a model.toml the
harvest can load."""

import argparse

import numpy as np
import pytest

from softarm.calibration import Calibration, load_model
from softarm.commands import calibrate as command
from softarm.errors import ParameterError


def _run(*argv: str) -> int:
    parser = argparse.ArgumentParser()
    command.add_parser(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["calibrate", *argv])
    return int(args.run(args))


def test_sim_calibration_writes_a_model(tmp_path, capsys) -> None:
    out = tmp_path / "model.toml"
    assert _run("--sim", "--seed", "3", "--poses", "30", "--out", str(out)) == 0
    cal = Calibration.load(out)
    assert cal.fit.samples == 30
    assert cal.fit.position_median_mm < 0.3
    assert load_model(out).n_actuators == 9
    assert np.all(np.abs(cal.actuator_gain - 1.0) < 0.1)
    captured = capsys.readouterr()
    assert "pose 30/30" in captured.err and "model:" in captured.out


def test_bad_options(tmp_path) -> None:
    with pytest.raises(SystemExit):  # checked while parsing (tests/test_files_hardening.py)
        _run("--sim", "--poses", "5")
    for name in ("hw.toml", "p.toml"):
        (tmp_path / name).write_text("")
    with pytest.raises(ParameterError, match="--plant"):
        _run("--config", str(tmp_path / "hw.toml"), "--plant", str(tmp_path / "p.toml"))


def test_harvest_model_option(tmp_path) -> None:
    from softarm.commands._plant import plant_options

    out = tmp_path / "model.toml"
    assert _run("--sim", "--seed", "1", "--poses", "25", "--out", str(out), "--quiet") == 0
    opts = plant_options(argparse.Namespace(sim=True, model=out))
    assert isinstance(opts["calibration"], Calibration)
    # On hardware too: the fit replaces the configured arm and channel gains.
    opts = plant_options(argparse.Namespace(sim=False, model=out))
    assert isinstance(opts["calibration"], Calibration)
