# ruff: noqa: E501  (OST_YAML keeps the long lines camera_calibration writes)
"""Camera calibration files: OpenCV FileStorage and ROS camera_info besides softarm's JSON."""

from pathlib import Path

import cv2
import numpy as np
import pytest

from softarm.errors import ConfigError
from softarm.vision import CameraModel

K = np.array([[629.4738, 0.0, 322.2486], [0.0, 629.6346, 237.5817], [0.0, 0.0, 1.0]])
D = np.array([0.084441, -0.164298, 0.000672, 0.001089, 0.0])

# What ROS' camera_calibration writes (ost.yaml) for a monocular camera.
OST_YAML = """\
image_width: 640
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [629.4738, 0.000000, 322.2486, 0.000000, 629.6346, 237.5817, 0.000000, 0.000000, 1.000000]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.084441, -0.164298, 0.000672, 0.001089, 0.000000]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1.000000, 0.000000, 0.000000, 0.000000, 1.000000, 0.000000, 0.000000, 0.000000, 1.000000]
projection_matrix:
  rows: 3
  cols: 4
  data: [634.5231, 0.000000, 322.7836, 0.000000, 0.000000, 635.7571, 237.8464, 0.000000, 0.000000, 0.000000, 1.000000, 0.000000]
"""


def test_none_distortion_means_no_distortion() -> None:
    model = CameraModel(K, None)
    assert model == CameraModel(K)
    assert not np.any(model.distortion)
    pix = model.project([[0.1, -0.05, 1.0]])
    np.testing.assert_allclose(pix, [[K[0, 0] * 0.1 + K[0, 2], -K[1, 1] * 0.05 + K[1, 2]]])


@pytest.mark.parametrize("name", ["cam.yml", "cam.xml"])
def test_opencv_round_trip_and_opencv_reads_it(tmp_path: Path, name: str) -> None:
    model = CameraModel(K, D, (640, 480))
    path = tmp_path / name
    model.save(path)
    assert CameraModel.load(path) == model
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    np.testing.assert_array_equal(fs.getNode("camera_matrix").mat(), K)
    np.testing.assert_array_equal(fs.getNode("distortion_coefficients").mat().ravel(), D)
    assert (fs.getNode("image_width").real(), fs.getNode("image_height").real()) == (640, 480)


def test_reads_the_opencv_calibration_sample_output(tmp_path: Path) -> None:
    # The keys samples/cpp/calibration.cpp writes, with its extra entries.
    path = tmp_path / "out_camera_data.yml"
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("calibration_time", "Sun Nov 22 10:00:00 2026")
    fs.write("nr_of_frames", 25)
    fs.write("image_width", 1280)
    fs.write("image_height", 720)
    fs.write("board_width", 9)
    fs.write("flags", 0)
    fs.write("camera_matrix", K)
    fs.write("distortion_coefficients", D.reshape(5, 1))
    fs.write("avg_reprojection_error", 0.21)
    fs.release()
    model = CameraModel.load(path)
    assert model == CameraModel(K, D, (1280, 720))


def test_reads_a_ros_camera_info_file(tmp_path: Path) -> None:
    path = tmp_path / "ost.yaml"
    path.write_text(OST_YAML)
    assert CameraModel.load(path) == CameraModel(K, D, (640, 480))


@pytest.mark.parametrize("dist", [D, np.r_[D, 0.01, -0.002, 0.0003], np.zeros(0)])
def test_ros_round_trip(tmp_path: Path, dist: np.ndarray) -> None:
    model = CameraModel(K, dist, (640, 480))
    path = tmp_path / "cam.yaml"
    model.save(path, camera_name="c2")
    text = path.read_text()
    for key in ("camera_name: c2", "rectification_matrix:", "projection_matrix:", "rows: 3"):
        assert key in text
    assert ("rational_polynomial" if dist.size == 8 else "plumb_bob") in text
    back = CameraModel.load(path)
    np.testing.assert_array_equal(back.matrix, K)
    np.testing.assert_array_equal(back.distortion[: dist.size], dist)
    assert not np.any(back.distortion[dist.size :])  # no distortion is written as zeros


def test_explicit_format_overrides_the_extension(tmp_path: Path) -> None:
    model = CameraModel(K, D, (640, 480))
    for fmt in ("json", "opencv", "ros"):
        path = tmp_path / f"cam-{fmt}.txt"
        model.save(path, format=fmt)
        assert CameraModel.load(path) == model
    path = tmp_path / "opencv.json"  # FileStorage's JSON, told from softarm's by content
    model.save(path, format="opencv")
    assert '"opencv-matrix"' in path.read_text() and CameraModel.load(path) == model


def test_bad_files_and_formats(tmp_path: Path) -> None:
    model = CameraModel(K, D)
    with pytest.raises(ConfigError, match="extension"):
        model.save(tmp_path / "cam.txt")
    with pytest.raises(ConfigError, match="format must be"):
        model.save(tmp_path / "cam.json", format="matlab")
    with pytest.raises(ConfigError, match="image size"):
        model.save(tmp_path / "cam.yaml")  # ROS needs the image size
    with pytest.raises(ConfigError, match="14 coefficients"):
        CameraModel(K, np.zeros(14), (640, 480)).save(tmp_path / "cam.yaml")
    cases = {
        "fisheye.yaml": (OST_YAML.replace("plumb_bob", "equidistant"), "equidistant"),
        "short.yaml": (OST_YAML.replace("0.000000, 1.000000]\ndist", "1.0]\ndist"), "3x3"),
        "nok.yml": ("%YAML:1.0\nimage_width: 640\n", "no camera_matrix"),
        "text.yml": ("this is not a calibration\n", "camera file"),
        "empty.yml": ("", "camera file"),
        "broken.json": ('{"camera_matrix": [1, 2', "JSON"),
    }
    for name, (text, match) in cases.items():
        path = tmp_path / name
        path.write_text(text)
        with pytest.raises(ConfigError, match=match):
            CameraModel.load(path)
