"""The cane pixels' source chosen in ``[perception] canes`` of hw.toml and by the
simulator's ``--cane-source``: each value parsed, a bad one one line naming the key or
the option."""

from __future__ import annotations

import re

import pytest

from softarm.cli import main
from softarm.commands.config import template
from softarm.config import dump_config, parse_config
from softarm.errors import ConfigError
from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.perception.cane_source import CANE_SOURCES
from softarm.perception_config import CANE_SOURCES as LISTED


def _with(perception: str) -> str:
    text = re.sub(r"(?m)^# ((T_C1_base|T_C2_EE|matrix) = )", r"\1", template())
    return text + "\n[perception]\n" + perception


def test_the_config_lists_the_same_sources() -> None:
    assert LISTED == CANE_SOURCES


@pytest.mark.parametrize("name", CANE_SOURCES)
def test_each_source_parses_and_round_trips(name: str) -> None:
    cfg = parse_config(_with(f'canes = "{name}"\n'), folder="/rig")
    assert cfg.perception is not None and cfg.perception.canes == name
    assert parse_config(dump_config(cfg), folder="/rig") == cfg


def test_the_default_is_the_colour_mask() -> None:
    cfg = parse_config(_with('stereo = "zed2"\n'), folder="/rig")
    assert cfg.perception is not None and cfg.perception.canes == "colour"
    assert SimRigOptions().cane_source == "colour"


@pytest.mark.parametrize("bad", ['"yolo"', '"Net"', "1", "true"])
def test_a_bad_source_is_one_error_naming_the_key(bad: str) -> None:
    with pytest.raises(ConfigError, match=r"perception\.canes.*must be one of"):
        parse_config(_with(f"canes = {bad}\n"), folder="/rig")


def test_the_template_names_the_key() -> None:
    assert '# canes = "colour"' in template()


def test_cane_source_outside_the_rendered_worlds_is_one_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["harvest", "--sim", "--cane-source", "net", "--berries", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("softarm harvest: error: --cane-source")


def test_a_bad_cane_source_option_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stop:
        main(["harvest", "--sim", "--world", "row", "--cane-source", "yolo"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "--cane-source" in err[-1] and "'yolo'" in err[-1]
