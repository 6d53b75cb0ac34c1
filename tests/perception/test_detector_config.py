"""The berry detector chosen in ``[perception] detector`` of hw.toml and by the
simulator's ``--detector``: each value parsed, a bad one one line naming the key."""

from __future__ import annotations

import re

import pytest

from softarm.cli import main
from softarm.commands.config import template
from softarm.config import dump_config, parse_config
from softarm.errors import ConfigError
from softarm.harvest.rigs.sim.options import SimRigOptions


def _with(perception: str) -> str:
    text = re.sub(r"(?m)^# ((T_C1_base|T_C2_EE|matrix) = )", r"\1", template())
    return text + "\n[perception]\n" + perception


@pytest.mark.parametrize("name", ["colour", "net", "net+colour"])
def test_each_detector_parses_and_round_trips(name: str) -> None:
    cfg = parse_config(_with(f'detector = "{name}"\n'), folder="/rig")
    assert cfg.perception is not None and cfg.perception.detector == name
    assert parse_config(dump_config(cfg), folder="/rig") == cfg


def test_the_default_is_the_colour_detector() -> None:
    cfg = parse_config(_with('stereo = "zed2"\n'), folder="/rig")
    assert cfg.perception is not None and cfg.perception.detector == "colour"
    assert SimRigOptions().detector == "colour"


def test_a_bad_detector_is_one_error_naming_the_key() -> None:
    with pytest.raises(ConfigError, match=r"perception\.detector.*must be one of"):
        parse_config(_with('detector = "yolo"\n'), folder="/rig")


def test_the_template_names_the_key() -> None:
    assert '# detector = "colour"' in template()


def test_harvest_detector_outside_the_rendered_worlds_is_one_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["harvest", "--sim", "--detector", "net", "--berries", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("softarm harvest: error: --detector")
