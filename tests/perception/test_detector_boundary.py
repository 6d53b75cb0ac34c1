"""The boundary class (``softarm detector train --boundary``): its target between two
touching fruit and on a lone one, the decoding that cuts touching fruit apart where it
marks them, the record that tells the detector (a record without the key is the old
network), the ONNX file as OpenCV runs it, and a training run deterministic in its
seed."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from detector_scenes import H, W, disc, training_scenes, write_folder
from jax_child import NEEDS_JAX, in_child

from softarm.errors import VisionError
from softarm.perception.berries import DetectorSettings
from softarm.perception.detector.boundary import fruit_parts
from softarm.perception.detector.instances import instances
from softarm.perception.detector.network import CLASSES, NetworkOutput, boundary_of
from softarm.perception.detector.train.samples import (
    BOUNDARY_FLAG,
    IGNORE,
    boundary_target,
    load_samples,
    stages,
)
from softarm.vision.camera_model import CameraModel


def _owner(*discs: np.ndarray) -> np.ndarray:
    owner = np.zeros((H, W), np.int32)
    for k, d in enumerate(discs, start=1):
        owner[d] = k
    return owner


def test_the_target_is_a_line_between_touching_fruit_and_none_on_a_lone_one() -> None:
    a, b = disc(40, 50, 9), disc(58, 50, 9)  # centres 18 px apart: they touch at x = 49
    target = boundary_target(_owner(a, b, disc(120, 60, 10)), radius=2)
    rows, cols = np.nonzero(target)
    assert rows.size > 0
    assert set(cols.tolist()) <= set(range(46, 53)), sorted(set(cols.tolist()))
    assert target[50, 48] and target[50, 49] and target[50, 50]  # both sides of the contact
    assert not target[:, 100:].any()  # the lone fruit
    assert not target[50, 35:46].any() and not target[50, 53:66].any()  # the fruit's insides
    assert not boundary_target(_owner(disc(60, 60, 12))).any()
    assert not boundary_target(np.zeros((H, W), np.int32)).any()


def test_samples_carry_the_flag_only_when_asked(tmp_path: Path) -> None:
    a, b = disc(40, 50, 9), disc(58, 50, 9)
    write_folder(tmp_path, [[("ripe", a, True), ("unripe", b, True)]])
    (plain,), _ = load_samples([tmp_path])
    (flagged,), _ = load_samples([tmp_path], boundary=True)
    assert not (plain.classes[plain.classes != IGNORE] & BOUNDARY_FLAG).any()
    marked = (flagged.classes != IGNORE) & ((flagged.classes & BOUNDARY_FLAG) > 0)
    assert marked.any() and not marked[:, :44].any() and not marked[:, 55:].any()
    assert np.array_equal(stages(flagged.classes), plain.classes)  # stages unchanged


def _touching(line: bool) -> NetworkOutput:
    """Two touching discs (radius 9, centres 17 px apart) at the network's size, one
    logistic heatmap peak of 0.7 between them (one fruit for the peak rule), and a
    boundary line across the contact where ``line``."""
    fruit = disc(40, 50, 9) | disc(57, 50, 9)
    probs = np.zeros((H, W, len(CLASSES)), np.float32)
    probs[..., 0] = ~fruit
    probs[..., 1] = fruit
    centres = np.zeros((H, W), np.float32)
    centres[50, 48] = 0.7
    boundary = np.zeros((H, W), np.float32)
    if line:
        boundary[:, 47:51] = 0.9
    return NetworkOutput(probs, centres, (2 * W, 2 * H), "logistic", boundary)


def test_a_boundary_line_cuts_two_touching_fruit_apart() -> None:
    camera = CameraModel.ideal(600.0, 2 * W, 2 * H)
    assert len(instances(_touching(False), camera, None, DetectorSettings())) == 1
    two = instances(_touching(True), camera, None, DetectorSettings())
    assert len(two) == 2
    xs = sorted(d.center[0] for d in two)
    assert abs(xs[0] - 2 * 40) < 4 and abs(xs[1] - 2 * 57) < 4, xs
    # the boundary pixels are given back: the two keep the blob's whole area
    whole = instances(_touching(False), camera, None, DetectorSettings())[0]
    assert (
        abs(sum(int(d.mask.sum()) for d in two) - int(whole.mask.sum())) < 0.05 * whole.mask.sum()
    )


def test_parts_give_the_boundary_back_and_keep_a_coreless_blob(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    binary = (disc(40, 50, 9) | disc(57, 50, 9) | disc(120, 50, 3)).astype(np.uint8)
    boundary = np.zeros((H, W), np.float32)
    boundary[:, 47:51] = 0.9
    boundary[45:56, 115:126] = 0.9  # the small fruit is boundary all through
    n, labels, stats = fruit_parts(binary, boundary)
    assert n == 4  # the background, two halves, the small fruit whole
    assert np.array_equal(labels > 0, binary > 0)
    assert sorted(int(stats[k, 4]) for k in range(1, n)) == sorted(
        int(np.count_nonzero(labels == k)) for k in range(1, n)
    )
    assert len({int(v) for v in labels[50, 31:66]}) == 2
    speck = boundary.copy()
    speck[48:54, 33:39] = 0.9  # a ring of boundary inside the left fruit
    speck[50:52, 35:37] = 0.0  # a piece of 2 x 2 px inside the band: no fruit of its own
    assert fruit_parts(binary, speck)[0] == 4
    monkeypatch.setattr("softarm.perception.detector.boundary.MIN_CORE", 1)
    assert fruit_parts(binary, speck)[0] == 5
    plain = fruit_parts(binary, None)
    assert plain[0] == 3
    none_marked = fruit_parts(binary, np.zeros((H, W), np.float32))
    assert none_marked[0] == 3 and np.array_equal(none_marked[1], plain[1])


def test_a_record_without_the_key_is_the_old_network(tmp_path: Path) -> None:
    weights = tmp_path / "w.onnx"
    assert boundary_of(weights) is False  # no record: the shipped weights'
    record = weights.with_suffix(".json")
    record.write_text(json.dumps({"epochs": 3, "heatmap": "logistic"}))
    assert boundary_of(weights) is False
    record.write_text(json.dumps({"boundary": True}))
    assert boundary_of(weights) is True
    for text in ('{"boundary": "yes"}', "{not json", "[1, 2]"):
        record.write_text(text)
        with pytest.raises(VisionError, match=r"w\.json"):
            boundary_of(weights)


def test_the_shipped_network_has_no_boundary() -> None:
    from softarm.perception.detector.network import DEFAULT_WEIGHTS, Network

    network = Network(DEFAULT_WEIGHTS)
    assert network.boundary is False
    assert network.run(np.zeros((48, 64, 3), np.uint8)).boundary is None


@NEEDS_JAX
def test_a_boundary_network_runs_in_opencv_as_in_jax(tmp_path: Path) -> None:
    done = in_child(
        """
        import json, sys
        from pathlib import Path
        import cv2
        import jax.numpy as jnp
        import numpy as np
        from softarm.errors import VisionError
        from softarm.perception.detector.network import Network, normalise
        from softarm.perception.detector.train.onnx_export import export_onnx, params_from_onnx
        from softarm.perception.detector.train.unet import apply, has_boundary, init_params

        path = Path(sys.argv[1])
        params = init_params(4, (4, 6, 8, 10), boundary=True)
        export_onnx(params, path)
        assert has_boundary(params_from_onnx(path)) and not has_boundary(init_params(4))
        image = np.random.default_rng(0).integers(0, 256, (48, 64, 3), np.uint8)
        x = normalise(image)
        jax_out = np.asarray(apply(params, jnp.asarray(x[None])))[0]
        net = cv2.dnn.readNetFromONNX(str(path))
        net.setInput(np.ascontiguousarray(x.transpose(2, 0, 1)[None]))
        cv_out = net.forward()[0].transpose(1, 2, 0)
        assert jax_out.shape == cv_out.shape == (48, 64, 7), (jax_out.shape, cv_out.shape)
        np.testing.assert_allclose(cv_out, jax_out, atol=1e-4)
        try:  # seven outputs and no record saying so: a clear error
            Network(path)
            raise AssertionError("no error")
        except VisionError as exc:
            assert "w.onnx" in str(exc)
        path.with_suffix(".json").write_text(json.dumps({"boundary": True}))
        out = Network(path).run(image)
        want = 1 / (1 + np.exp(-cv_out[..., 6]))
        np.testing.assert_allclose(out.boundary, want, atol=1e-5)
        print("ok")
        """,
        str(tmp_path / "w.onnx"),
    )
    assert done.returncode == 0 and "ok" in done.stdout, done.stderr


@NEEDS_JAX
def test_boundary_training_is_deterministic_in_its_seed_and_tells_the_detector(
    tmp_path: Path,
) -> None:
    data = tmp_path / "data"
    write_folder(data, training_scenes(4, seed=2))
    done = in_child(
        """
        import json, sys
        from pathlib import Path
        from softarm.errors import InputError
        from softarm.perception.detector.learned import LearnedDetector
        from softarm.perception.detector.train import train

        data, out = Path(sys.argv[1]), Path(sys.argv[2])
        runs = []
        for name, seed in (("a", 3), ("b", 3), ("c", 4)):
            train([data], out / f"{name}.onnx", 1, seed, widths=(4, 6, 8, 10), boundary=True)
            runs.append((out / f"{name}.onnx").read_bytes())
        assert runs[0] == runs[1] and runs[0] != runs[2]
        record = json.loads((out / "a.json").read_text())
        assert record["boundary"] is True
        assert LearnedDetector(out / "a.onnx").network.boundary is True
        # fine-tuned, it keeps its file's boundary class
        train([data], out / "d.onnx", 1, 5, start=out / "a.onnx")
        assert json.loads((out / "d.json").read_text())["boundary"] is True
        try:
            train([data], out / "e.onnx", 1, 5, start=out / "a.onnx", boundary=True)
            raise AssertionError("no error")
        except InputError as exc:
            assert "boundary" in str(exc)
        print("ok")
        """,
        str(data),
        str(tmp_path),
    )
    assert done.returncode == 0 and "ok" in done.stdout, done.stderr
