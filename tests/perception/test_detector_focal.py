"""The focal-loss heatmap (``softarm detector train --heatmap focal``): its targets on two
touching fruit, the loss's value on known inputs, the run-time decoding that splits
touching fruit at its sharp peaks, the record that tells the decoding, and a training
run deterministic in its seed."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from detector_scenes import H, W, disc, training_scenes, write_folder
from jax_child import NEEDS_JAX, in_child

from softarm.errors import VisionError
from softarm.perception.berries import DetectorSettings
from softarm.perception.detector.instances import instances
from softarm.perception.detector.network import CLASSES, NetworkOutput, heatmap_of
from softarm.vision.camera_model import CameraModel


@NEEDS_JAX
def test_targets_of_two_touching_discs_have_one_positive_at_each_centre() -> None:
    done = in_child(
        """
        import numpy as np
        from detector_scenes import disc
        from softarm.perception.detector.train.focal import sharpened
        from softarm.perception.detector.train.samples import _add_peak

        centres = np.zeros(disc(0, 0, 1).shape, np.float32)
        for cx in (40, 58):  # radius 9, centres 18 px apart: the discs touch
            _add_peak(centres, disc(cx, 50, 9))
        # as the augmentation leaves it: resized, the peaks below 1
        target = sharpened(centres[None] * np.float32(0.8))[0]
        rows, cols = np.nonzero(target == 1.0)
        assert sorted(zip(rows.tolist(), cols.tolist())) == [(50, 40), (50, 58)], (rows, cols)
        assert target[50, 49] < 0.01  # the contact between them is a negative
        assert np.array_equal(target[target < 1], 0.8 * centres[target < 1])
        # a tail cut off by a crop is no centre
        assert not (sharpened(centres[None, :, 62:] * np.float32(0.8)) == 1.0).any()
        print("ok")
        """
    )
    assert done.returncode == 0 and "ok" in done.stdout, done.stderr


@NEEDS_JAX
def test_the_focal_loss_has_centernets_value_on_known_inputs() -> None:
    done = in_child(
        """
        import math
        import numpy as np
        from softarm.perception.detector.train.focal import focal_loss, prior_bias

        target = np.array([[1.0, 0.5, 0.0]], np.float32)
        got = float(focal_loss(np.zeros((1, 3), np.float32), target))
        # p = 1/2: (1-p)^2 log p at the centre, (1-y)^4 p^2 log(1-p) elsewhere
        want = 0.25 * math.log(2) * (1 + 0.5**4 + 1)
        assert abs(got - want) < 1e-6, (got, want)
        sure = float(focal_loss(np.array([[20.0, -20.0, -20.0]], np.float32), target))
        assert 0 <= sure < 1e-6, sure
        # no centre in the batch: the negatives summed over one
        empty = float(focal_loss(np.zeros((2,), np.float32), np.zeros((2,), np.float32)))
        assert abs(empty - 2 * 0.25 * math.log(2)) < 1e-6, empty
        assert abs(1 / (1 + math.exp(-prior_bias())) - 0.1) < 1e-9
        print("ok")
        """
    )
    assert done.returncode == 0 and "ok" in done.stdout, done.stderr


def _touching(heatmap: str) -> NetworkOutput:
    """Two touching discs (radius 5, centres 9 px apart: closer than the logistic rule's
    PEAK_SEPARATION) and a sharp peak of 0.5 at each centre, at the network's size."""
    a, b = disc(40, 50, 5), disc(49, 50, 5)
    fruit = a | b
    probs = np.zeros((H, W, len(CLASSES)), np.float32)
    probs[..., 0] = ~fruit
    probs[..., 1] = fruit
    centres = np.zeros((H, W), np.float32)
    centres[50, 40] = centres[50, 49] = 0.5
    centres[50, 41] = centres[50, 48] = 0.2
    return NetworkOutput(probs, centres, (2 * W, 2 * H), heatmap)


def test_a_focal_heatmap_splits_touching_fruit_at_its_sharp_peaks() -> None:
    camera = CameraModel.ideal(600.0, 2 * W, 2 * H)
    one = instances(_touching("logistic"), camera, None, DetectorSettings())
    assert len(one) == 1  # peaks under 0.6, and 9 px apart: one fruit
    two = instances(_touching("focal"), camera, None, DetectorSettings())
    assert len(two) == 2
    xs = sorted(d.center[0] for d in two)
    assert abs(xs[0] - 2 * 40) < 4 and abs(xs[1] - 2 * 49) < 4, xs


def test_the_heatmap_kind_is_read_from_the_record_beside_the_weights(tmp_path: Path) -> None:
    weights = tmp_path / "w.onnx"
    assert heatmap_of(weights) == "logistic"  # no record: the shipped weights'
    record = weights.with_suffix(".json")
    record.write_text(json.dumps({"epochs": 3}))
    assert heatmap_of(weights) == "logistic"  # a record from before the focal loss
    record.write_text(json.dumps({"heatmap": "focal"}))
    assert heatmap_of(weights) == "focal"
    for text in ('{"heatmap": "sharp"}', "{not json", "[1, 2]"):
        record.write_text(text)
        with pytest.raises(VisionError, match=r"w\.json"):
            heatmap_of(weights)


@NEEDS_JAX
def test_focal_training_is_deterministic_in_its_seed_and_tells_the_detector(
    tmp_path: Path,
) -> None:
    data = tmp_path / "data"
    write_folder(data, training_scenes(4, seed=2))
    done = in_child(
        """
        import json, sys
        from pathlib import Path
        from softarm.perception.detector.learned import LearnedDetector
        from softarm.perception.detector.train import train

        data, out = Path(sys.argv[1]), Path(sys.argv[2])
        runs = []
        for name, seed in (("a", 3), ("b", 3), ("c", 4)):
            train([data], out / f"{name}.onnx", 1, seed, widths=(4, 6, 8, 10), heatmap="focal")
            runs.append((out / f"{name}.onnx").read_bytes())
        assert runs[0] == runs[1] and runs[0] != runs[2]
        assert json.loads((out / "a.json").read_text())["heatmap"] == "focal"
        assert LearnedDetector(out / "a.onnx").network.heatmap == "focal"
        # fine-tuned, it keeps its file's heatmap
        train([data], out / "d.onnx", 1, 5, start=out / "a.onnx")
        assert json.loads((out / "d.json").read_text())["heatmap"] == "focal"
        print("ok")
        """,
        str(data),
        str(tmp_path),
    )
    assert done.returncode == 0 and "ok" in done.stdout, done.stderr


def test_an_unknown_heatmap_is_one_usage_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from softarm.cli import main

    args = ["detector", "train", "--data", str(tmp_path), "--out", str(tmp_path / "w.onnx")]
    with pytest.raises(SystemExit) as exit_:
        main([*args, "--heatmap", "sharp"])
    assert exit_.value.code == 2 and "--heatmap" in capsys.readouterr().err
