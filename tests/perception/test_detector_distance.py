"""The distance target (``softarm detector train --distance``): its scale-free hills on
fruit of different sizes, the watershed that splits two touching discs the heatmap's
peaks merge, the record that tells the detector, the ONNX file as OpenCV runs it, and
training deterministic in its seed, fresh or added to a trained network."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from detector_scenes import H, W, disc, training_scenes, write_folder
from jax_child import NEEDS_JAX, in_child

from softarm.perception.berries import DetectorSettings
from softarm.perception.detector.distance import distance_pieces, markers
from softarm.perception.detector.instances import instances
from softarm.perception.detector.network import CLASSES, NetworkOutput, distance_of
from softarm.perception.detector.train.distance_target import distance_target
from softarm.perception.detector.train.samples import load_samples
from softarm.vision.camera_model import CameraModel

# Two touching fruit of radii 12 and 5 px whose centres lie 15 px apart: the small one
# overlaps the large one's edge by 2 px (a neck 7 px wide).
BIG, SMALL = disc(50, 60, 12), disc(65, 60, 5)


def _owner() -> np.ndarray:
    owner = np.zeros((H, W), np.int32)
    owner[BIG] = 1
    owner[SMALL & ~BIG] = 2
    return owner


def test_the_target_is_one_at_each_centre_and_near_zero_at_each_edge_whatever_the_size() -> None:
    target = distance_target(_owner())
    assert target[~(BIG | SMALL)].max() == 0.0
    assert target[60, 50] == 1.0 and target[60, 66] == 1.0  # both hills' tops, 12 and 5 px
    assert target[60, 38] < 0.1 and target[60, 62] < 0.1  # the big one's edges
    assert target[60, 63] < 0.2 and target[60, 70] < 0.2  # the small one's, at the neck too
    # lone discs of 4 and 16 px: the same shape of hill, half-way up at half the radius
    lone = np.zeros((H, W), np.int32)
    lone[disc(30, 60, 4)], lone[disc(100, 60, 16)] = 1, 2
    hills = distance_target(lone)
    for cx, r in ((30, 4), (100, 16)):
        assert hills[60, cx] == 1.0 and hills[60, cx + r] < 0.15
        assert 0.45 < hills[60, cx + r // 2] < 0.75
    speck = np.zeros((H, W), np.int32)
    speck[60, 100] = 3  # a fruit of one pixel is all centre
    assert distance_target(speck)[60, 100] == 1.0


def test_samples_carry_the_target_only_when_asked(tmp_path: Path) -> None:
    write_folder(tmp_path, [[("ripe", BIG, True), ("unripe", SMALL & ~BIG, True)]])
    (plain,), _ = load_samples([tmp_path])
    (with_it,), _ = load_samples([tmp_path], distance=True)
    assert plain.distance is None
    assert with_it.distance is not None
    np.testing.assert_allclose(with_it.distance, distance_target(_owner()), atol=1e-6)


def _output(distance: np.ndarray | None) -> NetworkOutput:
    """A network's output for the two touching discs: all ripe, and the broad logistic
    heatmap of the shipped network (one hump over both, as the merge the docs report)."""
    fruit = BIG | SMALL
    probs = np.zeros((H, W, len(CLASSES)), np.float32)
    probs[..., 0] = np.where(fruit, 0.05, 0.95)
    probs[..., 1] = np.where(fruit, 0.95, 0.05)
    yy, xx = np.mgrid[:H, :W]
    centres = np.exp(-((xx - 54) ** 2 + (yy - 60) ** 2) / (2 * 6.0**2)).astype(np.float32)
    d = None if distance is None else distance.astype(np.float32)
    return NetworkOutput(probs, centres, (W, H), "logistic", None, d)


def test_the_watershed_splits_two_touching_discs_the_heatmap_merges() -> None:
    camera = CameraModel.ideal(200.0, W, H)
    merged = instances(_output(None), camera, None, DetectorSettings())
    assert len(merged) == 1  # the heatmap's one peak: one fruit
    target = distance_target(_owner())
    assert markers(BIG | SMALL, target)[0] == 2
    split = instances(_output(target), camera, None, DetectorSettings())
    assert len(split) == 2
    big, small = sorted(split, key=lambda d: -d.radius)
    assert abs(big.center[0] - 50) < 1.5 and abs(small.center[0] - 65) < 1.5
    assert 10.5 < big.radius < 12.5 and 3.5 < small.radius < 5.5
    pieces = distance_pieces(BIG | SMALL, target)
    assert sum(int(p.sum()) for p in pieces) == int((BIG | SMALL).sum())  # all kept, once


def test_one_fruit_stays_whole_and_the_record_tells_the_detector(tmp_path: Path) -> None:
    owner = np.zeros((H, W), np.int32)
    owner[BIG] = 1
    (piece,) = distance_pieces(BIG, distance_target(owner))
    assert np.array_equal(piece, BIG)
    weights = tmp_path / "w.onnx"
    assert distance_of(weights) is False  # no record: the shipped weights'
    weights.with_suffix(".json").write_text(json.dumps({"boundary": True}))
    assert distance_of(weights) is False
    weights.with_suffix(".json").write_text(json.dumps({"distance": True}))
    assert distance_of(weights) is True


@NEEDS_JAX
def test_a_distance_network_runs_in_opencv_as_in_jax(tmp_path: Path) -> None:
    done = in_child(
        """
        import json, sys
        from pathlib import Path
        import cv2
        import jax.numpy as jnp
        import numpy as np
        from softarm.perception.detector.network import Network, normalise
        from softarm.perception.detector.train.onnx_export import export_onnx, params_from_onnx
        from softarm.perception.detector.train.unet import apply, init_params, with_distance

        path = Path(sys.argv[1])
        params = with_distance(init_params(4, (4, 6, 8, 10)), 1)
        export_onnx(params, path)
        path.with_suffix(".json").write_text(json.dumps({"distance": True}))
        assert params_from_onnx(path)["head"][0].shape[-1] == 7
        image = np.random.default_rng(0).integers(0, 256, (48, 64, 3), np.uint8)
        x = normalise(image)
        jax_out = np.asarray(apply(params, jnp.asarray(x[None])))[0]
        net = cv2.dnn.readNetFromONNX(str(path))
        net.setInput(np.ascontiguousarray(x.transpose(2, 0, 1)[None]))
        cv_out = net.forward()[0].transpose(1, 2, 0)
        np.testing.assert_allclose(cv_out, jax_out, atol=1e-4)
        out = Network(path).run(image)
        assert out.boundary is None
        np.testing.assert_allclose(out.distance, 1 / (1 + np.exp(-cv_out[..., 6])), atol=1e-5)
        print("ok")
        """,
        str(tmp_path / "w.onnx"),
    )
    assert done.returncode == 0 and "ok" in done.stdout, done.stderr


@NEEDS_JAX
def test_distance_training_is_deterministic_and_adds_the_output_to_a_trained_network(
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
            train([data], out / f"{name}.onnx", 1, seed, widths=(4, 6, 8, 10), distance=True)
            runs.append((out / f"{name}.onnx").read_bytes())
        assert runs[0] == runs[1] and runs[0] != runs[2]
        assert json.loads((out / "a.json").read_text())["distance"] is True
        assert LearnedDetector(out / "a.onnx").network.distance is True
        # a plain network fine-tuned with --distance gets the output; one that has it keeps it
        train([data], out / "p.onnx", 1, 5, widths=(4, 6, 8, 10))
        assert json.loads((out / "p.json").read_text())["distance"] is False
        train([data], out / "q.onnx", 1, 5, start=out / "p.onnx", distance=True)
        train([data], out / "r.onnx", 1, 5, start=out / "q.onnx")
        for name in ("q", "r"):
            assert json.loads((out / f"{name}.json").read_text())["distance"] is True
            network = LearnedDetector(out / f"{name}.onnx").network
            assert network.distance is True and network.boundary is False
        print("ok")
        """,
        str(data),
        str(tmp_path / "out"),
    )
    assert done.returncode == 0 and "ok" in done.stdout, done.stderr


def test_a_part_without_a_hill_is_no_fruit() -> None:
    owner = np.zeros((H, W), np.int32)
    owner[BIG] = 1
    flat = np.where(BIG, 0.3, 0.0).astype(np.float32)  # fruit-coloured, no fruit's shape
    assert distance_pieces(BIG, flat) == []
    assert len(distance_pieces(BIG, distance_target(owner))) == 1
