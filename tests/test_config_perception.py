"""The ``[perception]`` table of hw.toml (issue 24, item 2): the stereo source, its
calibration resolved against the config's folder, each bad key one line naming it, and
``config check`` opening the stereo file."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from softarm import cli
from softarm.commands.config import template
from softarm.config import dump_config, load_config, parse_config
from softarm.errors import ConfigError
from softarm.vision import CameraModel
from softarm.vision.stereo_camera import StereoCamera
from softarm.vision.stereo_files import write_stereo


def _ready(perception: str = "") -> str:
    """The template with its calibration uncommented, and ``perception`` appended."""
    text = re.sub(r"(?m)^# ((T_C1_base|T_C2_EE|matrix) = )", r"\1", template())
    return text + ("\n[perception]\n" + perception if perception else "")


def _stereo(path: Path) -> None:
    cam = CameraModel.ideal(700.0, 640, 480)
    T = np.eye(4)
    T[0, 3] = 0.12
    write_stereo(StereoCamera.pair(cam, cam, T), path)


def test_the_template_section_uncommented_parses() -> None:
    text = re.sub(r"(?m)^# (\[perception\]|stereo =|device =|calibration =|berries =|survey =)",
                  r"\1", _ready())  # fmt: skip
    p = parse_config(text, folder="/rig").perception
    assert p is not None and p.stereo == "zed2" and p.devices() == (0,) and p.survey
    assert p.calibration_path == str(Path("/rig") / "stereo.yml")


def test_a_pair_resolves_its_files_and_round_trips() -> None:
    cfg = parse_config(_ready('stereo = "pair"\nleft = "l.mp4"\nright = 2\n'), folder="/rig")
    assert cfg.perception is not None
    assert cfg.perception.devices() == (str(Path("/rig") / "l.mp4"), 2)
    assert cfg.perception.survey  # C2 surveys the canes unless told not to
    assert parse_config(dump_config(cfg), folder="/rig") == cfg


def test_the_survey_can_be_turned_off_and_round_trips() -> None:
    cfg = parse_config(_ready("survey = false\n"), folder="/rig")
    assert cfg.perception is not None and cfg.perception.survey is False
    assert parse_config(dump_config(cfg), folder="/rig") == cfg


@pytest.mark.parametrize(
    ("body", "key"),
    [
        ('stereo = "kinect"', "perception.stereo"),
        ('stereo = "zed2"\nleft = 1', "perception.left"),
        ('stereo = "pair"\nleft = 0', "perception.right"),
        ('berries = "paint"', "perception.berries"),
        ('survey = "yes"', "perception.survey"),
        ("device = true", "perception.device"),
        ("calibration = 3", "perception.calibration"),
        ("lens = 1", "perception.lens"),
    ],
)
def test_a_bad_key_is_one_line_naming_it(body: str, key: str) -> None:
    with pytest.raises(ConfigError, match=re.escape(key)) as err:
        parse_config(_ready(body + "\n"))
    assert "\n" not in str(err.value)


def test_config_check_opens_the_stereo_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "hw.toml"
    path.write_text(_ready('calibration = "stereo.yml"\n'))
    assert cli.main(["config", "check", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "perception.calibration" in err[0] and "stereo.yml" in err[0]
    (tmp_path / "stereo.yml").write_text("%YAML:1.0\n---\nM1: 3\n")
    assert cli.main(["config", "check", str(path)]) == 2
    assert "perception.calibration" in capsys.readouterr().err
    _stereo(tmp_path / "stereo.yml")
    assert cli.main(["config", "check", str(path)]) == 0
    assert load_config(path).perception is not None
