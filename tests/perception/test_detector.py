"""The learned berry detector at run time: the shipped weights (read through OpenCV's DNN,
without JAX), a missing or corrupt weights file, bad images, the detector choice, and
``softarm detect`` on a picture."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from detector_scenes import H, W, disc, draw, sphere_depth

from softarm.cli import main
from softarm.errors import InputError, ParameterError, VisionError
from softarm.perception.berries import DetectorSettings
from softarm.perception.detector.choice import (
    DEFAULT_DETECTOR,
    current_detector,
    detector,
    use_detector,
)
from softarm.perception.detector.instances import instances
from softarm.perception.detector.learned import LearnedDetector
from softarm.perception.detector.network import (
    CLASSES,
    DEFAULT_WEIGHTS,
    RUN_SIDE,
    Network,
    NetworkOutput,
)
from softarm.vision.camera_model import CameraModel

CAMERA = CameraModel.ideal(300.0, W, H)


def test_the_weights_ship_in_the_package_and_are_small() -> None:
    assert DEFAULT_WEIGHTS.is_file()
    assert DEFAULT_WEIGHTS.stat().st_size <= 10 * 1024 * 1024


def test_the_shipped_weights_load_without_jax() -> None:
    code = (
        "import sys; sys.modules['jax'] = None; sys.modules['optax'] = None; "
        "sys.modules['onnx'] = None\n"
        "import numpy as np\n"
        "from softarm.perception.detector.learned import LearnedDetector\n"
        "from softarm.vision.camera_model import CameraModel\n"
        "d = LearnedDetector()\n"
        "d.detect_berries(np.zeros((48, 64, 3), np.uint8), CameraModel.ideal(60.0, 64, 48))\n"
        "print('ok', 'jax' in sys.modules and sys.modules['jax'] is not None)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok False"


def test_a_missing_weights_file_is_one_error_naming_it(tmp_path: Path) -> None:
    path = tmp_path / "nowhere.onnx"
    with pytest.raises(VisionError, match=r"nowhere\.onnx: no such file"):
        Network(path)


@pytest.mark.parametrize("content", [b"", b"not an onnx file at all", b"\x08\x07" * 50])
def test_a_corrupt_weights_file_is_one_error_naming_it(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "broken.onnx"
    path.write_bytes(content)
    with pytest.raises(VisionError, match=r"broken\.onnx"):
        LearnedDetector(path)


def test_a_truncated_copy_of_the_shipped_weights_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "cut.onnx"
    path.write_bytes(DEFAULT_WEIGHTS.read_bytes()[:5000])
    with pytest.raises(VisionError, match=r"cut\.onnx"):
        LearnedDetector(path)


def test_the_network_gives_one_probability_per_class_at_its_resolution() -> None:
    net = Network()
    out = net.run(np.zeros((720, 1280, 3), np.uint8))
    assert out.probabilities.shape == (RUN_SIDE * 720 // 1280, RUN_SIDE, len(CLASSES))
    np.testing.assert_allclose(out.probabilities.sum(axis=2), 1.0, atol=1e-4)
    assert out.size == (1280, 720) and out.scale == 1280 / RUN_SIDE
    assert out.upsample(out.centres).shape == (720, 1280)


def test_a_network_runs_at_the_longest_side_it_is_given() -> None:
    out = LearnedDetector(max_side=320).output(np.zeros((720, 1280, 3), np.uint8))
    assert out.probabilities.shape[:2] == (180, 320) and out.scale == 4.0
    small = Network(max_side=2048).run(np.zeros((120, 160, 3), np.uint8))
    assert small.probabilities.shape[:2] == (120, 160)  # never enlarged


@pytest.mark.parametrize("side", [0, 7, -640, 640.0, True, "640"])
def test_a_bad_longest_side_is_an_input_error_naming_it(side: object) -> None:
    with pytest.raises(InputError, match="max_side"):
        Network(max_side=side)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "image",
    [
        np.zeros((H, W), np.uint8),
        np.zeros((H, W, 3), np.float32),
        np.zeros((0, W, 3), np.uint8),
        np.zeros((H, W, 4), np.uint8),
        "picture.png",
        None,
    ],
)
def test_bad_images_are_a_vision_error(image: object) -> None:
    with pytest.raises(VisionError):
        LearnedDetector().detect_berries(image, CAMERA)  # type: ignore[arg-type]


@pytest.mark.parametrize("shape", [(1, 1, 3), (3, 200, 3), (H, W, 3)])
def test_plain_or_tiny_images_give_a_list_not_a_crash(shape: tuple[int, int, int]) -> None:
    image = np.zeros(shape, np.uint8)
    camera = CameraModel.ideal(100.0, shape[1], shape[0])
    dets = LearnedDetector().detect_berries(image, camera)
    assert isinstance(dets, list)


def test_depth_of_the_wrong_size_is_a_vision_error() -> None:
    with pytest.raises(VisionError):
        LearnedDetector().detect_berries(
            np.zeros((H, W, 3), np.uint8), CAMERA, np.ones((H, W + 1), np.float32)
        )


def test_detections_carry_a_stage_and_masks_of_their_box() -> None:
    image = draw([("ripe", disc(50, 60, 10)), ("unripe", disc(110, 60, 10))])
    for det in LearnedDetector().detect_berries(image, CAMERA):
        assert det.stage in ("ripe", "turning", "unripe")
        assert det.ripeness == ("ripe" if det.stage == "ripe" else "unripe")
        x, y, w, h = det.box
        assert det.mask.shape == (h, w) and det.mask_offset == (x, y)


def test_the_default_detector_is_the_colour_one_and_a_bad_name_is_refused() -> None:
    assert DEFAULT_DETECTOR == "colour" and current_detector() == "colour"
    with pytest.raises(ParameterError, match="detector must be one of"):
        detector("yolo")
    with pytest.raises(ParameterError):
        use_detector("yolo")
    assert current_detector() == "colour"


def test_the_package_entry_point_dispatches_to_the_chosen_detector() -> None:
    from softarm.perception import detect_berries

    image = draw([("ripe", disc(50, 60, 10))])
    try:
        use_detector("net")
        assert current_detector() == "net"
        net = detect_berries(image, CAMERA)
        assert all(hasattr(d, "stage") for d in net)
    finally:
        use_detector("colour")
    colour = detect_berries(image, CAMERA)
    assert len(colour) == 1 and colour[0].ripeness == "ripe"


def test_detect_prints_and_draws_a_picture(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    image = tmp_path / "bush.jpg"
    cv2.imwrite(str(image), draw([("ripe", disc(50, 60, 12)), ("unripe", disc(110, 60, 12))]))
    out = tmp_path / "annotated.png"
    assert main(["detect", str(image), "--out", str(out), "--detector", "colour"]) == 0
    text = capsys.readouterr().out
    assert "detect: 2 berries (1 ripe, 0 turning, 1 unripe) by colour" in text
    drawn = cv2.imread(str(out))
    assert drawn is not None and drawn.shape == (H, W, 3)
    assert main(["detect", str(image), "--detector", "net"]) == 0


def test_detect_with_depth_prints_positions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    image = tmp_path / "bush.png"
    cv2.imwrite(str(image), draw([("ripe", disc(80, 60, 12))]))
    depth = tmp_path / "bush_depth.png"
    # A fruit's cap 1 m away (a flat depth is no fruit: the depth check drops it).
    cv2.imwrite(
        str(depth), np.round(1000 * sphere_depth(80, 60, 12, 1.0, 1500.0)).astype(np.uint16)
    )
    camera = tmp_path / "camera.json"
    CameraModel.ideal(1500.0, W, H).save(camera)  # 24 px across at 1 m: a 16 mm fruit
    args = ["detect", str(image), "--depth", str(depth), "--camera", str(camera)]
    assert main([*args, "--detector", "colour"]) == 0
    line = capsys.readouterr().out.splitlines()[0]
    assert line.startswith("ripe") and line.endswith(" m") and ", 1.0" in line


def test_detect_on_a_file_that_is_no_image_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "notes.png"
    bad.write_text("hello")
    assert main(["detect", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not a PNG, JPEG, BMP, TIFF or WebP image" in err[0]


def test_detect_with_depth_of_another_size_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    image = tmp_path / "bush.png"
    cv2.imwrite(str(image), draw([]))
    depth = tmp_path / "d.png"
    cv2.imwrite(str(depth), np.zeros((10, 10), np.uint16))
    assert main(["detect", str(image), "--depth", str(depth)]) == 2
    assert "--depth" in capsys.readouterr().err


def test_input_error_is_what_missing_labels_raise(tmp_path: Path) -> None:
    from softarm.perception.detector.labels import read_coco

    with pytest.raises(InputError, match="no such file"):
        read_coco(tmp_path / "none.json")


def _output(fruit: np.ndarray, stage: np.ndarray, peaks: list[tuple[int, int]]) -> NetworkOutput:
    """A network output of probability 1 for class ``stage`` on ``fruit`` pixels and
    Gaussian centre peaks."""
    h, w = fruit.shape
    probs = np.zeros((h, w, len(CLASSES)), np.float32)
    probs[..., 0] = ~fruit
    for k in range(1, 4):
        probs[..., k] = fruit & (stage == k)
    yy, xx = np.mgrid[:h, :w]
    centres = np.zeros((h, w), np.float32)
    for cy, cx in peaks:
        centres = np.maximum(centres, np.exp(-((yy - cy) ** 2 + (xx - cx) ** 2) / 8.0))
    return NetworkOutput(probs, centres.astype(np.float32), (w * 2, h * 2))


def test_touching_fruit_split_at_their_centre_peaks_and_staged_by_majority() -> None:
    a, b = disc(40, 50, 9), disc(56, 50, 9)  # touching discs, centres 16 px apart
    fruit = (a | b)[:, :]
    stage = np.where(a, 1, 3)  # ripe left, unripe right (the overlap goes to a)
    one = instances(_output(fruit, stage, []), CameraModel.ideal(600.0, 2 * W, 2 * H), None,
                    DetectorSettings())  # fmt: skip
    assert len(one) == 1
    two = instances(_output(fruit, stage, [(50, 40), (50, 56)]),
                    CameraModel.ideal(600.0, 2 * W, 2 * H), None, DetectorSettings())  # fmt: skip
    assert sorted(d.stage for d in two) == ["ripe", "unripe"]
    left = min(two, key=lambda d: d.center[0])
    assert abs(left.center[0] - 2 * 40 - 0.5) < 3 and abs(left.center[1] - 2 * 50 - 0.5) < 2
    assert left.mask.shape == (left.box[3], left.box[2])
