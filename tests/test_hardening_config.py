"""``config check`` and the harvest refuse what they would misuse (issue 42, items 6, 9
and 13): an empty ``[perception]`` table is the ZED2 with ``stereo.yml`` (not no table),
a ``stereo.yml`` with an implausible baseline, ``R``/``T`` contradicting
``T_left_right``, a NaN or an empty file is one ConfigError line, and camera sources
that are no OpenCV device (-1, 2**63-1, one device for both eyes) are refused by the
config and by :class:`OpenCVCamera` (no segfault, no raw ``cv2.error``)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from softarm import cli
from softarm.commands.config import template
from softarm.config import parse_config
from softarm.errors import ConfigError
from softarm.vision import CameraModel
from softarm.vision.stereo_camera import StereoCamera
from softarm.vision.stereo_files import read_stereo, write_stereo

CAMERA = CameraModel.ideal(700.0, 640, 480)


def _ready(perception: str | None = None) -> str:
    """The template with its calibration uncommented, and a ``[perception]`` table of
    ``perception`` appended (None: no table)."""
    text = re.sub(r"(?m)^# ((T_C1_base|T_C2_EE|matrix) = )", r"\1", template())
    return text if perception is None else text + "\n[perception]\n" + perception


@pytest.fixture(scope="module")
def good(tmp_path_factory: pytest.TempPathFactory) -> str:
    """A plausible stereo.yml (the right eye 12 cm on the left's +x), as text."""
    T = np.eye(4)
    T[0, 3] = 0.12
    path = tmp_path_factory.mktemp("stereo") / "stereo.yml"
    write_stereo(StereoCamera.pair(CAMERA, CAMERA, T), path)
    return path.read_text()


def _with_translation(text: str, x: float, y: float = 0.0) -> str:
    """``text`` (a stereo.yml) with the right eye at (x, y, 0) in both R/T and
    T_left_right (consistent, so only the pair's plausibility is at stake)."""
    tlr = f"[ 1., 0., 0., {x!r}, 0., 1., 0., {y!r}, 0., 0., 1., 0., 0., 0., 0., 1. ]"
    text = re.sub(r"(T_left_right:.*?data: )\[[^\]]*\]", lambda m: m.group(1) + tlr, text,
                  flags=re.S)  # fmt: skip
    return re.sub(r"(\nT:.*?data: )\[[^\]]*\]", lambda m: m.group(1) + f"[ {-x!r}, {-y!r}, 0. ]",
                  text, flags=re.S)  # fmt: skip


@pytest.fixture
def rig(tmp_path: Path) -> Path:
    """A ready hw.toml with an empty [perception] table (its stereo.yml not written)."""
    (tmp_path / "hw.toml").write_text(_ready(""))
    return tmp_path


def _check(folder: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, list[str]]:
    status = cli.main(["config", "check", str(folder / "hw.toml")])
    return status, capsys.readouterr().err.strip().splitlines()


def test_an_empty_perception_table_is_the_default_stereo_source(
    rig: Path, good: str, capsys: pytest.CaptureFixture[str]
) -> None:
    perception = parse_config(_ready("")).perception
    assert perception is not None and perception.stereo == "zed2"
    assert perception.devices() == (0,) and perception.calibration == "stereo.yml"
    assert parse_config(_ready()).perception is None
    status, err = _check(rig, capsys)  # stereo.yml is missing: not ready
    assert status == 2 and len(err) == 1 and "perception.calibration" in err[0]
    (rig / "stereo.yml").write_text(good)
    assert _check(rig, capsys)[0] == 0


@pytest.mark.parametrize(
    ("x", "y", "message"),
    [(0.0, 0.0, "baseline is 0 mm"), (1e-9, 0.0, "baseline"), (-0.12, 0.0, r"\+x"),
     (1e308, 0.0, "baseline"), (0.0, 0.12, r"\+x")],
)  # fmt: skip
def test_an_implausible_pair_is_one_line(
    rig: Path, good: str, capsys: pytest.CaptureFixture[str], x: float, y: float, message: str
) -> None:
    (rig / "stereo.yml").write_text(_with_translation(good, x, y))
    with pytest.raises(ConfigError, match=message):
        read_stereo(rig / "stereo.yml")
    status, err = _check(rig, capsys)
    assert status == 2 and len(err) == 1, err
    assert "perception.calibration" in err[0] and re.search(message, err[0])


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda t: re.sub(r"(\nT:.*?data: )\[[^\]]*\]", r"\1[ 0.12, 0., 0. ]", t, flags=re.S),
         "contradict T_left_right"),
        (lambda t: re.sub(r"(T_left_right:.*?data: \[ )1\.", r"\1nan", t, flags=re.S),
         "T_left_right is not a valid opencv-matrix"),
        (lambda t: re.sub(r"(T_left_right:.*?data: \[ )1\.", r"\1.nan", t, flags=re.S),
         "T_left_right holds a value that is not finite"),
        (lambda t: re.sub(r"(M1:.*?data: \[ )700\.", r"\1.inf", t, flags=re.S),
         "M1 holds a value that is not finite"),
        (lambda t: "", "is empty"),
        (lambda t: "\n  \n", "is empty"),
        (lambda t: "\x00\x01 junk", "holds a NUL byte"),
        (lambda t: "a: [[[", "cannot parse stereo file .*Missing , between"),
        (lambda t: re.sub(r"image_width: \d+\n", "", t), "image_width"),
        (lambda t: re.sub(r"(T_left_right:\s*!!opencv-matrix\s*rows: )4", r"\g<1>3", t),
         "T_left_right"),
    ],
)  # fmt: skip
def test_a_broken_stereo_file_is_one_line(
    rig: Path, good: str, capsys: pytest.CaptureFixture[str], edit: object, message: str
) -> None:
    (rig / "stereo.yml").write_text(edit(good))  # type: ignore[operator]
    with pytest.raises(ConfigError, match=message):
        read_stereo(rig / "stereo.yml")
    status, err = _check(rig, capsys)
    assert status == 2 and len(err) == 1 and message.split()[0] in err[0], err


@pytest.mark.parametrize("source", ["-1", str(2**63 - 1), "100", '""'])
def test_a_camera_source_that_is_no_device_is_refused(source: str) -> None:
    text, n = re.subn(r"(?m)^source = 1\b", f"source = {source}", _ready())
    assert n == 1
    with pytest.raises(ConfigError, match=r"calibration\.c2\.source") as err:
        parse_config(text)
    assert "\n" not in str(err.value)
    with pytest.raises(ConfigError, match=r"perception\.device"):
        parse_config(_ready(f"device = {source}\n"))


def test_one_device_for_both_eyes_is_refused() -> None:
    with pytest.raises(ConfigError, match=r"perception\.right .*another device"):
        parse_config(_ready('stereo = "pair"\nleft = 1\nright = 1\n'))
    with pytest.raises(ConfigError, match=r"perception\.right"):
        parse_config(
            _ready('stereo = "pair"\nleft = "eye.mp4"\nright = "./eye.mp4"\n'), folder="/r"
        )
    pair = parse_config(_ready('stereo = "pair"\nleft = 1\nright = 2\n')).perception
    assert pair is not None and pair.devices() == (1, 2)


def test_opencv_camera_refuses_what_is_no_source() -> None:
    """Each is an InputError. -1 crashed the driver (exit 139) and a name that is not
    UTF-8 reached OpenCV: run where a crash cannot take the tests down."""
    code = (
        "from softarm.hardware.camera import OpenCVCamera\n"
        "from softarm.errors import SoftarmError\n"
        "for source in (-1, 2**63 - 1, 100, True, '', 'cam\\udcff.mp4', 1.5):\n"
        "    try:\n        OpenCVCamera(source)\n"
        "    except SoftarmError as exc:\n        print(type(exc).__name__, exc)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    lines = done.stdout.strip().splitlines()
    assert done.returncode == 0 and len(lines) == 7, done
    assert all(line.startswith("InputError camera source") for line in lines), lines


def test_config_check_refuses_every_pair_the_harvest_refuses() -> None:
    """What StereoCamera refuses when the harvest builds it, read_stereo's pair check
    refuses first, so that `config check` never says ready for it."""
    from softarm.errors import VisionError
    from softarm.vision.calibration_checks import pair_problems
    from softarm.vision.stereo_camera import StereoCamera

    rng = np.random.default_rng(42)
    translations = [*rng.normal(0.0, 0.1, (200, 3)), (0.1, 0.1, 0.0), (0.1, 0.0, -0.1)]
    refused = 0
    for t in translations:
        T = np.eye(4)
        T[:3, 3] = t
        try:
            StereoCamera(CAMERA, CAMERA, np.eye(4), T)
        except VisionError:
            refused += 1
            assert pair_problems(T), t
    assert refused > 100  # the sample does reach the refusals
