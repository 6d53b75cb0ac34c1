"""The [plant] table: every key typed and range-checked, one-line errors naming the key,
and the simulated rig built from it."""

from __future__ import annotations

import dataclasses
import math
import pickle
from pathlib import Path

import pytest

from softarm.cli import main
from softarm.errors import ConfigError, ParameterError
from softarm.sim.arm import PlantConfig
from softarm.sim.plant_file import (
    PLANT_KEYS,
    load_plant_file,
    plant_from_mapping,
    validate_plant_value,
)


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "plant.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_keys_are_the_dataclass_fields() -> None:
    assert set(PLANT_KEYS) == {f.name for f in dataclasses.fields(PlantConfig)}


def test_defaults_lie_in_their_ranges() -> None:
    for key in PLANT_KEYS:
        validate_plant_value(key, getattr(PlantConfig(), key))


def test_file_sets_keys_and_keeps_defaults(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        '[plant]\nmodel = "cosserat"\npressure_tau = 1\nhysteresis_psi = 5.0\n'
        "gravity = [9.81, 0, 0]\n\n[other]\nignored = true\n",
    )
    plant = load_plant_file(path)
    assert plant.pressure_tau == 1.0 and isinstance(plant.pressure_tau, float)
    assert plant.hysteresis_psi == 5.0
    assert plant.model == "cosserat"
    assert plant.gravity == (9.81, 0.0, 0.0)
    assert plant.geometry_spread == PlantConfig().geometry_spread
    assert pickle.loads(pickle.dumps(plant)) == plant


BAD_VALUES = [
    ("pressure_tau", -1, "plant.pressure_tau = -1: must be in [0.001, 10] s"),
    ("pressure_tau", 11.0, "must be in [0.001, 10] s"),
    ("pressure_tau", "0.3", "must be a number"),
    ("pressure_tau", True, "must be a number"),
    ("pressure_tau", math.nan, "must be in"),
    ("hysteresis_psi", 25.0, "plant.hysteresis_psi = 25.0: must be in [0, 20] psi"),
    ("geometry_spread", 0.5, "plant.geometry_spread"),
    ("gain_spread", -0.01, "plant.gain_spread"),
    ("twist_spread", 1.0, "plant.twist_spread"),
    ("position_noise", 0.1, "plant.position_noise"),
    ("angle_noise", 1.0, "plant.angle_noise"),
    ("cutoff", 0.0, "plant.cutoff"),
    ("max_psi", 200.0, "plant.max_psi"),
    ("model", "fem", "plant.model = 'fem': must be one of ['pcc', 'cosserat']"),
    ("gravity", [0, 0], "plant.gravity = [0, 0]: must be a list of 3 finite numbers"),
    ("gravity", [0, 0, -981], "plant.gravity"),
    ("gravity", "down", "plant.gravity"),
    ("stiffness", 1.0, "plant.stiffness: unknown plant key"),
]


@pytest.mark.parametrize(("key", "value", "message"), BAD_VALUES)
def test_bad_values_name_the_key(key: str, value: object, message: str) -> None:
    with pytest.raises(ParameterError) as err:
        plant_from_mapping({key: value})
    assert message in str(err.value)
    assert "\n" not in str(err.value)
    if key in PLANT_KEYS:  # the dataclass checks the same ranges
        with pytest.raises(ParameterError, match=f"^PlantConfig.{key} = "):
            PlantConfig(**{key: value})


def test_validate_names_the_caller_s_table() -> None:
    assert validate_plant_value("pressure_tau", 2, where="sweep.plant") == 2.0
    with pytest.raises(ParameterError, match=r"^sweep\.plant\.pressure_tau = 0: "):
        validate_plant_value("pressure_tau", 0, where="sweep.plant")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[plant]\npressure_tau = -1\n", "plant.pressure_tau = -1: must be in [0.001, 10] s"),
        ("[plant]\npresure_tau = 0.3\n", "plant.presure_tau: unknown plant key"),
        ('[plant]\nhysteresis_psi = "5"\n', "plant.hysteresis_psi = '5': must be a number"),
        ("[plant\npressure_tau = 1\n", "not valid TOML"),
        ("pressure_tau = 0.3\n", "no [plant] table"),
        ("plant = 3\n", "plant must be a table"),
    ],
)
def test_bad_files_are_one_line_config_errors(tmp_path: Path, text: str, message: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(ConfigError) as err:
        load_plant_file(path)
    assert message in str(err.value)
    assert str(path) in str(err.value)
    assert "\n" not in str(err.value)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read plant file"):
        load_plant_file(tmp_path / "absent.toml")


def test_sim_rig_builds_the_configured_plant() -> None:
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    plant = PlantConfig(pressure_tau=0.3, hysteresis_psi=4.0, max_psi=60.0)
    rig = build_sim_rig(SimRigOptions(n_berries=1, seed=3, plant=plant))
    assert rig.plant.sim.config is plant
    assert rig.plant.sim.dynamics.tau == 0.3
    assert rig.plant.sim.dynamics.max_psi == 60.0
    assert (rig.plant.sim.hysteresis.width == 4.0).all()


@pytest.mark.parametrize("command", [["harvest", "--sim"], ["demo"]])
def test_cli_bad_plant_file_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: list[str]
) -> None:
    path = write(tmp_path, "[plant]\npressure_tau = -1\n")
    extra = ["--out", str(tmp_path / "out")] if command == ["demo"] else []
    assert main([*command, "--plant", str(path), "--berries", "1", *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "plant.pressure_tau = -1: must be in [0.001, 10] s" in err
    assert not (tmp_path / "out").exists()  # nothing written before the check


def test_cli_plant_needs_sim(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write(tmp_path, "[plant]\npressure_tau = 0.3\n")
    cfg = tmp_path / "hw.toml"
    assert main(["config", "init", str(cfg)]) == 0
    capsys.readouterr()
    assert main(["harvest", "--config", str(cfg), "--plant", str(path)]) == 2
    assert "--plant: works with --sim only" in capsys.readouterr().err
