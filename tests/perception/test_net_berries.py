"""The pixel-network candidate detector (softarm.perception.net_berries) and its
training script (softarm.experiments.train_pixel_net), on tiny synthetic images."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from softarm.errors import VisionError
from softarm.experiments.train_pixel_net import Mlp, onnx_model, sample_pixels, train
from softarm.perception.net_berries import N_CLASSES, N_FEATURES, NetDetector, pixel_features
from softarm.vision.camera_model import CameraModel

CAMERA = CameraModel.ideal(300.0, 160, 120)
BACKGROUND = (60, 110, 70)  # BGR: leaf green
RIPE = (40, 8, 25)  # black-purple
UNRIPE = (30, 30, 200)  # red


def _scene() -> tuple[np.ndarray, np.ndarray]:
    """A 160×120 image with a ripe and an unripe disc, and its truth (0, 1, 2)."""
    img = np.full((120, 160, 3), BACKGROUND, np.uint8)
    truth = np.zeros((120, 160), np.uint8)
    yy, xx = np.mgrid[:120, :160]
    for (cx, cy), colour, code in (((45, 60), RIPE, 1), ((115, 60), UNRIPE, 2)):
        disc = (xx - cx) ** 2 + (yy - cy) ** 2 < 12**2
        img[disc] = colour
        truth[disc] = code
    return img, truth


@pytest.fixture(scope="module")
def trained() -> tuple[Mlp, NetDetector]:
    img, truth = _scene()
    rng = np.random.default_rng(0)
    per = {"fruit": 300, "background": 600, "ring": 200, "dark": 100, "clutter": 0}
    x, y = sample_pixels(img, truth, rng, per)
    mlp = train(x, y, hidden=8, epochs=30, batch=256, rate=0.03)
    return mlp, NetDetector(onnx_model(mlp))


def test_features_have_their_shape_and_dtype() -> None:
    f = pixel_features(_scene()[0])
    assert f.shape == (120, 160, N_FEATURES) and f.dtype == np.float32
    assert np.isfinite(f).all() and f.min() >= -1.0 and f.max() <= 1.0


def test_opencv_dnn_runs_the_network_as_numpy_does(trained: tuple[Mlp, NetDetector]) -> None:
    mlp, net = trained
    x = pixel_features(_scene()[0]).reshape(-1, N_FEATURES)[::7]
    np.testing.assert_allclose(net._forward(x), mlp.logits(x), atol=1e-4)


def test_classes_and_detections_on_a_tiny_scene(trained: tuple[Mlp, NetDetector]) -> None:
    _, net = trained
    img, truth = _scene()
    classes = net.classes(img)
    assert classes.shape == (120, 160) and classes.dtype == np.uint8
    assert set(np.unique(classes)) <= set(range(N_CLASSES))
    assert np.mean(classes == truth) > 0.95
    mask = net.fruit_mask(img)
    assert mask.shape == (120, 160) and mask.dtype == np.uint8
    dets = sorted(net.detect_berries(img, CAMERA), key=lambda d: d.center[0])
    assert [d.ripeness for d in dets] == ["ripe", "unripe"]
    assert abs(dets[0].center[0] - 45) < 2 and abs(dets[0].center[1] - 60) < 2


@pytest.mark.parametrize(
    "image",
    [
        np.zeros((0, 0, 3), np.uint8),
        np.zeros((12, 16, 3), np.float32),
        np.zeros((12, 16), np.uint8),
        [[0, 0, 0]],
    ],
    ids=["empty", "float", "grey", "list"],
)
def test_bad_images_raise_a_vision_error(trained: tuple[Mlp, NetDetector], image: object) -> None:
    _, net = trained
    with pytest.raises(VisionError, match="image"):
        net.detect_berries(image, CAMERA)  # type: ignore[arg-type]
    with pytest.raises(VisionError, match="image"):
        net.classes(image)  # type: ignore[arg-type]


#: The network measured in docs/perception.md ("Which detector"), not shipped.
MEASURED = Path(__file__).parents[2] / "docs/data/perception/berry_pixels_h8.onnx"


@pytest.mark.parametrize(
    "level", [0, 255, BACKGROUND], ids=["all black", "saturated by sun", "leaf green"]
)
def test_frames_without_fruit_give_no_detection(level: object) -> None:
    # The measured network, not the toy one above: a network that never saw black
    # pixels may call them fruit, and the blob stage then takes the frame for a berry.
    net = NetDetector(MEASURED)
    frame = np.full((120, 160, 3), level, np.uint8)
    assert net.detect_berries(frame, CAMERA) == []


def test_a_missing_or_broken_model_is_a_vision_error(tmp_path: Path) -> None:
    with pytest.raises(VisionError, match="no pixel network"):
        NetDetector(tmp_path / "absent.onnx")
    with pytest.raises(VisionError):
        NetDetector(b"not an onnx model")


def test_the_training_script_runs_on_one_rendered_bush(tmp_path: Path) -> None:
    from perception_world import rendered_world

    rendered_world(900).close()  # skips where this machine cannot render
    from softarm.experiments.train_pixel_net import main

    out = tmp_path / "pixels.onnx"
    main(["--out", str(out), "--train", "900", "900", "--epochs", "1", "--no-validate"])
    assert 0 < out.stat().st_size < 10_000_000
    net = NetDetector(out)
    assert net.classes(np.full((8, 8, 3), 128, np.uint8)).shape == (8, 8)


def test_the_evaluation_bushes_are_refused(tmp_path: Path) -> None:
    from softarm.experiments.train_pixel_net import main

    with pytest.raises(SystemExit):
        main(["--out", str(tmp_path / "x.onnx"), "--train", "610", "620"])
