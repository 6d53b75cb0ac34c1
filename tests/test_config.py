"""softarm.config: the shipped default, save/load round trip, and every validation error."""

from __future__ import annotations

import math
import re
from importlib import resources
from pathlib import Path

import pytest

from softarm.config import (
    CalibrationConfig,
    CameraConfig,
    Config,
    GainsConfig,
    HarvestConfig,
    SerialConfig,
    default_config,
    load_config,
    parse_config,
    save_config,
)
from softarm.errors import ConfigError

DEFAULT = resources.files("softarm.data").joinpath("blackberry.toml").read_text("utf-8")


def test_default_matches_the_blackberry_arm() -> None:
    c = default_config()
    assert [s.radius for s in c.arm.sections] == [0.028, 0.022, 0.018]
    assert all(s.rest_length == 0.15 and s.lower == 0.0 for s in c.arm.sections)
    assert all(s.upper == pytest.approx(70.0 / 2100.0) for s in c.arm.sections)
    assert [s.offset for s in c.arm.sections] == [0.012, 0.012, 0.060]
    assert [s.twist for s in c.arm.sections] == [math.pi / 3, math.pi / 3, 0.0]
    assert len(c.channels.names) == 9 and c.channels.voltage_range == (0.0, 5.0)
    assert c.channels.full_scale_psi == pytest.approx(0.5e6 / 6894.757, rel=1e-6)
    assert c.channels.metres_per_psi == 1.0 / 2100.0


def test_round_trip(tmp_path: Path) -> None:
    rot = ((0.0, -1.0, 0.0, 0.1), (1.0, 0.0, 0.0, -0.2), (0.0, 0.0, 1.0, 1.2), (0, 0, 0, 1.0))
    base = default_config()
    config = Config(
        arm=base.arm,
        gains=GainsConfig(
            {"hybrid_alpha": 0.5, "schedule": "smooth", "axis_mask": [True, True, False]}
        ),
        calibration=CalibrationConfig(
            c1=CameraConfig(0, ((700.0, 0, 640.0), (0, 700.0, 360.0), (0, 0, 1.0)), (0.1, -0.2)),
            c2=CameraConfig("/dev/video2", file="c2 intrinsics.npz"),
            T_C1_base=rot,
            T_C2_EE=((1.0, 0, 0, 0), (0, 1.0, 0, 0), (0, 0, 1.0, 0.05), (0, 0, 0, 1.0)),
        ),
        serial=SerialConfig(port='COM3 "x"', baud=57600, retries=0, startup_delay_s=0.0),
    )
    path = tmp_path / "arm.toml"
    save_config(config, path)
    assert load_config(path) == config
    save_config(base, path)
    assert load_config(path) == base


def test_missing_file_and_bad_toml(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"nope\.toml"):
        load_config(tmp_path / "nope.toml")
    with pytest.raises(ConfigError, match="not valid TOML"):
        parse_config("[arm\nradius = ")


SECTION0 = "radius = 0.028\n"
POSE_BAD_ROW = "T_C1_base = [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,1,1]]\n"
POSE_SKEW = "T_C1_base = [[1,1,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n"
POSE_MIRROR = "T_C1_base = [[-1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n"


def edit(old: str, new: str, count: int = 1) -> str:
    assert old in DEFAULT, old
    return DEFAULT.replace(old, new, count)


CASES = [
    (edit(SECTION0, ""), "arm.sections[0].radius is required"),
    (edit("radius = 0.022", "radius = -0.022"), "arm.sections[1].radius must be > 0"),
    (edit("radius = 0.022", 'radius = "big"'), "arm.sections[1].radius must be a finite"),
    (edit("radius = 0.022", "radius = nan"), "arm.sections[1].radius must be a finite"),
    (edit("radius = 0.022", "radius = true"), "arm.sections[1].radius must be a finite"),
    (edit("rest_length = 0.15", "rest_length = 0"), "arm.sections[0].rest_length must be > 0"),
    (edit("lower = 0.0", "lower = 0.04"), "arm.sections[0].upper must be greater than lower"),
    (edit("offset = 0.060", "offset = -0.06"), "arm.sections[2].offset must be >= 0"),
    (edit("twist = 0.0", "twist = inf"), "arm.sections[2].twist must be a finite"),
    (edit(SECTION0, SECTION0 + "radus = 1\n"), "unknown key 'arm.sections[0].radus'"),
    (edit("upper = 0.03333333333333333  #", "upper = 0.05  #"), "arm.sections[0] elongation"),
    (re.sub(r"\[\[arm\.sections\]\].*?\n\n", "", DEFAULT, flags=re.S), "arm is required"),
    ("arm = 3\n", "arm must be a table"),
    ("[arm]\nsections = []\n", "arm.sections must be a non-empty array"),
    (edit("[gains]", "[gains]\nalpha = {x = 1}"), "gains.alpha must be a finite number, bool"),
    (edit("[gains]", "[gains]\nalpha = nan"), "gains.alpha must be a finite number"),
    (edit("[gains]", "[gains]\nalpha = 0.5"), "unknown key 'gains.alpha' (a softarm.Gains"),
    (edit("[gains]", "[gains]\nhybrid_gamma = 'x'"), "gains.hybrid_gamma is refused by"),
    (edit("[gains]", "[gains]\nschedule = 'nope'"), "gains.schedule is refused by softarm.Gains"),
    (edit("[gains]", "[gains]\nhybrid_alpha = 9.0"), "gains.hybrid_alpha is refused by"),
    (edit("[calibration]  #", "[calibration]\n" + POSE_BAD_ROW + "#"), "last row"),
    (edit("[calibration]  #", "[calibration]\n" + POSE_SKEW + "#"), "orthonormal"),
    (edit("[calibration]  #", "[calibration]\n" + POSE_MIRROR + "#"), "determinant"),
    (
        edit("[calibration]  #", "[calibration]\nT_C2_EE = [[1, 0], [0, 1]]\n#"),
        "calibration.T_C2_EE must be a 4x4",
    ),
    (edit("source = 0", "source = 0\nmatrix = [[1, 0, 0]]"), "calibration.c1.matrix must be a 3x3"),
    (edit("source = 1", "source = 1.5"), "calibration.c2.source must be a device index"),
    (edit("source = 1", "source = 1\nfile = 3"), "calibration.c2.file must be a path"),
    (edit("source = 1", "source = 1\nfocal = 3"), "unknown key 'calibration.c2.focal'"),
    (edit('"Dev1/ao8"]', '"Dev1/ao8", "Dev1/ao9"]'), "channels.names must name 9 channels"),
    (edit('"Dev1/ao8"]', '"Dev1/ao0"]'), "channels.names must not repeat"),
    (edit('"Dev1/ao8"]', "8]"), "channels.names must be an array of channel-name strings"),
    (edit("voltage_range = [0.0, 5.0]", "voltage_range = [5.0, 0.0]"), "channels.voltage_range"),
    (edit("voltage_range = [0.0, 5.0]", "voltage_range = [0.0]"), "channels.voltage_range"),
    (edit("p_max = 70.0", "p_max = 80.0"), "channels.p_max must not exceed full_scale_psi"),
    (edit("p_max = 70.0", "p_max = 60.0"), "outside what channels.p_max = 60.0 psi"),
    (edit("max_rate_psi_per_s = 100.0", "max_rate_psi_per_s = 0"), "channels.max_rate_psi_per_s"),
    (edit("watchdog_timeout_s = 0.5", "watchdog_timeout_s = -1"), "channels.watchdog_timeout_s"),
    (edit("metres_per_psi = 0.", "metres_per_psi = -0."), "channels.metres_per_psi must be > 0"),
    (edit("full_scale_psi = 72.51886623", "full_scale_psi = 0"), "channels.full_scale_psi"),
    (edit('port = "/dev/ttyACM0"', "port = 5"), "serial.port must be a non-empty string"),
    (edit("baud = 115200", "baud = 9600.5"), "serial.baud must be a positive integer"),
    (edit("retries = 2", "retries = -1"), "serial.retries must be a non-negative integer"),
    (edit("timeout_s = 0.5\nretries", "timeout_s = 0\nretries"), "serial.timeout_s must be > 0"),
    (edit("startup_delay_s = 2.0", "startup_delay_s = -2.0"), "serial.startup_delay_s must be >="),
    (edit("[serial]", "[serail]\nx = 1\n[serial]"), "unknown key 'serail'"),
]


@pytest.mark.parametrize(("text", "message"), CASES)
def test_validation_errors_name_the_key(text: str, message: str) -> None:
    with pytest.raises(ConfigError, match=re.escape(message)):
        parse_config(text, source="test.toml")


def test_error_message_carries_the_value() -> None:
    with pytest.raises(ConfigError, match=r"test\.toml: arm\.sections\[1\]\.radius .* got -0\.022"):
        parse_config(edit("radius = 0.022", "radius = -0.022"), source="test.toml")


HARVEST_OK = """[harvest]
period = 0.1
approach = [0, 0, 1]
settle_steps = 5
marker_timeout = 2
#"""


def test_harvest_tuning_and_marker_geometry_from_the_file(tmp_path: Path) -> None:
    text = edit("[calibration]  #", "[calibration]\nberry_tag = 0.03\n#").replace(
        "T_EE_cube = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -0.05], [0, 0, 0, 1]]",
        "T_EE_cube = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -0.07], [0, 0, 0, 1]]",
    )
    text = re.sub(r"\nberry_tag = 0\.012[^\n]*", "", text).replace("[harvest]  #", HARVEST_OK)
    c = parse_config(text, source="test.toml")
    assert c.harvest == HarvestConfig(
        period=0.1, approach=(0.0, 0.0, 1.0), settle_steps=5, marker_timeout=2.0
    )
    assert c.harvest.fine_timeout == HarvestConfig().fine_timeout  # the rest: defaults
    assert c.calibration.berry_tag == 0.03
    assert c.calibration.T_EE_cube[2][3] == -0.07
    save_config(c, tmp_path / "c.toml")
    assert load_config(tmp_path / "c.toml") == c


def test_shipped_defaults_are_the_harvest_defaults() -> None:
    c = default_config()
    assert c.harvest == HarvestConfig()
    assert c.calibration.berry_tag == 0.012  # the paper's 12 mm tag
    assert c.calibration.T_EE_cube[2][3] == -0.05  # the cube 5 cm behind the gripper frame


def test_template_shows_every_harvest_key_at_its_default() -> None:
    """The shipped file's commented ``[harvest]`` block names every HarvestConfig field
    with the default the dataclass declares (the one declaration of each value)."""
    import dataclasses
    import tomllib

    block = DEFAULT.split("\n[harvest]", 1)[1].split("\n[", 1)[0]
    shown = {}
    for line in block.splitlines():
        m = re.match(r"# (\w+ = .*?)(?:  #.*)?$", line)
        if m:
            shown.update(tomllib.loads(m.group(1)))
    defaults = HarvestConfig()
    expected = {f.name: getattr(defaults, f.name) for f in dataclasses.fields(HarvestConfig)}
    assert {k: tuple(v) if isinstance(v, list) else v for k, v in shown.items()} == expected


HARVEST_BAD = [
    ("periodd = 0.1", "unknown key 'harvest.periodd'"),
    ("period = -0.1", "harvest.period must be finite and > 0, got -0.1"),
    ("period = 'fast'", "harvest.period must be a finite number, got 'fast'"),
    ("period = true", "harvest.period must be a finite number"),
    ("settle_steps = 2.5", "harvest.settle_steps must be an integer >= 1"),
    ("reapproaches = -1", "harvest.reapproaches must be an integer >= 0, got -1"),
    ("reapproaches = true", "harvest.reapproaches must be an integer >= 0"),
    ("approach = [1, 1, 0]", "harvest.approach must be a unit vector"),
    ("approach = [0, 1]", "harvest.approach must be a unit vector"),
    ("approach_cone_deg = 90", "harvest.approach_cone_deg must be in [0, 90)"),
    ("grasp_offset = -0.01", "harvest.grasp_offset must be finite and >= 0"),
    ("fine_budget = nan", "harvest.fine_budget must be a finite number"),
]


@pytest.mark.parametrize(("line", "message"), HARVEST_BAD)
def test_harvest_errors_name_the_key(line: str, message: str) -> None:
    with pytest.raises(ConfigError, match=re.escape(message)):
        parse_config(edit("[harvest]  #", f"[harvest]\n{line}\n#"), source="test.toml")


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("berry_tag = 0", "calibration.berry_tag must be > 0"),
        ("berry_tag = '12 mm'", "calibration.berry_tag must be a finite number"),
        ("T_EE_cube = [[1, 0], [0, 1]]", "calibration.T_EE_cube must be a 4x4"),
        ("T_EE_cube = [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]", "T_EE_cube must have an ortho"),
    ],
)
def test_marker_geometry_errors_name_the_key(line: str, message: str) -> None:
    text = re.sub(r"\n(T_EE_cube|berry_tag) = [^\n]*", "", DEFAULT)
    text = text.replace("[calibration]  #", f"[calibration]\n{line}\n#")
    with pytest.raises(ConfigError, match=re.escape(message)):
        parse_config(text, source="test.toml")
