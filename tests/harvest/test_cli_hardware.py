"""``softarm harvest --config`` without hardware: a clear message and exit status 2."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from softarm.cli import main
from softarm.config import default_config, save_config


def _calibrated(path) -> None:
    c = default_config()
    eye = tuple(tuple(r) for r in np.eye(4).tolist())
    k = ((900.0, 0.0, 640.0), (0.0, 900.0, 360.0), (0.0, 0.0, 1.0))
    cam1 = replace(c.calibration.c1, matrix=k, distortion=(0.0,) * 5)
    cam2 = replace(c.calibration.c2, matrix=k, distortion=(0.0,) * 5)
    cal = replace(c.calibration, T_C1_base=eye, T_C2_EE=eye, c1=cam1, c2=cam2)
    save_config(replace(c, calibration=cal), path)


def test_no_hardware_exits_2_with_a_clear_message(tmp_path, capsys) -> None:
    _calibrated(tmp_path / "hw.toml")
    assert main(["harvest", "--config", str(tmp_path / "hw.toml")]) == 2
    err = capsys.readouterr().err
    assert "hardware not available" in err and "Traceback" not in err
    assert "--sim" in err


def test_uncalibrated_config_exits_2_naming_the_keys(tmp_path, capsys) -> None:
    save_config(default_config(), tmp_path / "hw.toml")
    assert main(["harvest", "--config", str(tmp_path / "hw.toml")]) == 2
    assert "calibration.T_C1_base" in capsys.readouterr().err
