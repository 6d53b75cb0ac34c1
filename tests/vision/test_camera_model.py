from pathlib import Path

import numpy as np
import pytest

from softarm.errors import ConfigError, ParameterError, ShapeError
from softarm.vision import CameraModel


def test_save_load_round_trip(tmp_path: Path, camera: CameraModel) -> None:
    path = tmp_path / "cam.json"
    camera.save(path)
    assert CameraModel.load(path) == camera
    assert '"format": "softarm.camera/1"' in path.read_text()


def test_project_and_normalize_are_inverse(camera: CameraModel) -> None:
    rng = np.random.default_rng(0)
    pts = np.c_[rng.uniform(-0.6, 0.6, (50, 1)), rng.uniform(-0.35, 0.35, (50, 1)), np.ones(50)]
    np.testing.assert_allclose(camera.normalize(camera.project(pts)), pts[:, :2], atol=1e-10)


def test_bad_models(tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match="matrix"):
        CameraModel(np.zeros((3, 3)))
    with pytest.raises(ShapeError, match="distortion"):
        CameraModel(np.eye(3), [0.1, 0.2, 0.3])
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "other"}')
    with pytest.raises(ConfigError, match="format"):
        CameraModel.load(bad)
    with pytest.raises(ConfigError, match="cannot read"):
        CameraModel.load(tmp_path / "missing.json")
