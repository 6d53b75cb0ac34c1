"""The detector's tools: COCO labels as CVAT and Label Studio write them, the scoring of
``softarm detector evaluate`` against a hand-made COCO file whose figures are known, and
``softarm detector train`` end to end on a tiny generated dataset."""

from __future__ import annotations

import importlib.util
import json
import subprocess
from pathlib import Path

import cv2
import numpy as np
import pytest
from detector_scenes import H, W, disc, draw, training_scenes, write_folder
from jax_child import NEEDS_JAX, in_child

from softarm.cli import main
from softarm.perception.detector.choice import detector
from softarm.perception.detector.evaluate import evaluate
from softarm.perception.detector.labels import _decode_counts, read_coco, stage_of


def _known(tmp_path: Path, instances: bool = False) -> Path:
    """Two images whose colour detections are known: image 0 has ripe A and B, unripe
    C (all drawn) and ripe D labelled but not drawn; image 1 has ripe E drawn but not
    labelled and a turning F drawn in the ripe colour."""
    scenes = [
        [
            ("ripe", disc(40, 35, 10), True), ("ripe", disc(115, 35, 10), True),
            ("unripe", disc(40, 85, 10), True), ("ripe", disc(115, 85, 10), False),
        ],
        [("turning", disc(110, 60, 10), False)],
    ]  # fmt: skip
    path = write_folder(tmp_path, scenes, instances=instances)
    # Draw E (unlabelled) and F (in the ripe colour) into image 1 by hand.
    cv2.imwrite(
        str(tmp_path / "images" / "000001.png"),
        draw([("ripe", disc(40, 60, 10)), ("ripe", disc(110, 60, 10))]),
    )
    return path


EXPECTED = {
    "images": 2,
    "detections": 5,
    "false_detections": 1,
    "precision": 0.8,
    "ripe_precision": 0.5,
    "recall_ripe": 0.6667,
    "recall": 0.8,
    "stage_right": 0.75,
}


@pytest.mark.parametrize("instances", [False, True])
def test_evaluate_gives_the_known_figures(tmp_path: Path, instances: bool) -> None:
    labels = _known(tmp_path, instances)
    out = tmp_path / "out"
    figures = evaluate(detector("colour"), labels, tmp_path, out=out)
    assert {k: figures[k] for k in EXPECTED} == EXPECTED
    assert figures["confusion"]["ripe"] == {"ripe": 2, "turning": 0, "unripe": 0, "missed": 1}
    assert figures["confusion"]["turning"]["ripe"] == 1
    assert figures["confusion"]["unripe"]["unripe"] == 1
    assert sorted(p.name for p in out.iterdir()) == ["000000.png", "000001.png", "metrics.json"]
    assert json.loads((out / "metrics.json").read_text())["precision"] == 0.8


def test_evaluate_on_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    labels = _known(tmp_path)
    args = ["detector", "evaluate", "--images", str(tmp_path / "images"), "--labels", str(labels)]
    assert main([*args, "--detector", "colour", "-q"]) == 0
    shown = json.loads(capsys.readouterr().out.split("\ndetector evaluate")[0])
    assert {k: shown[k] for k in EXPECTED} == EXPECTED


def test_evaluate_with_labels_that_are_not_coco_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "labels.json"
    bad.write_text('{"annotations": []}')
    assert main(["detector", "evaluate", "--images", str(tmp_path), "--labels", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not COCO" in err[0]


def _encode(counts: list[int]) -> str:
    """pycocotools' rleToString, for the decoder's round trip."""
    out = []
    for i, c in enumerate(counts):
        x = c - counts[i - 2] if i > 2 else c
        more = True
        while more:
            ch = x & 0x1F
            x >>= 5
            more = (x != -1) if ch & 0x10 else (x != 0)
            if more:
                ch |= 0x20
            out.append(chr(ch + 48))
    return "".join(out)


def test_compressed_rle_decodes_as_pycocotools_encodes() -> None:
    rng = np.random.default_rng(4)
    counts = [int(v) for v in rng.integers(0, 400, 40)]
    assert _decode_counts(_encode(counts)) == counts


def test_cvat_and_label_studio_exports_are_read(tmp_path: Path) -> None:
    (tmp_path / "photos").mkdir()
    cv2.imwrite(str(tmp_path / "photos" / "IMG_0042.jpg"), np.zeros((H, W, 3), np.uint8))
    mask = disc(50, 60, 10)
    column = mask.T.ravel()  # COCO RLE runs down the columns
    edges = np.flatnonzero(np.diff(np.concatenate([[0], column.astype(int), [0]])))
    runs = np.diff(np.concatenate([[0], edges, [column.size]])).tolist()
    coco = {
        "images": [
            {"id": 7, "file_name": "/data/upload/3/3f2a9c1b-IMG_0042.jpg", "width": W, "height": H}
        ],
        "categories": [
            {"id": 1, "name": "Ripe blackberry"}, {"id": 2, "name": "Leaf"},
            {"id": 3, "name": "fruit"},
        ],
        "annotations": [
            {"id": 1, "image_id": 7, "category_id": 1, "iscrowd": 1,
             "segmentation": {"size": [H, W], "counts": runs[:-1]}},
            {"id": 2, "image_id": 7, "category_id": 1, "iscrowd": 1,
             "segmentation": {"size": [H, W], "counts": _encode(runs[:-1])}},
            {"id": 3, "image_id": 7, "category_id": 3, "bbox": [100, 40, 20, 20],
             "attributes": {"stage": "turning"}},
            {"id": 4, "image_id": 7, "category_id": 2, "bbox": [0, 0, 10, 10]},
        ],
    }  # fmt: skip
    (tmp_path / "export.json").write_text(json.dumps(coco))
    (item,) = read_coco(tmp_path / "export.json", tmp_path / "photos")
    objects = item.objects()
    assert [o.stage for o in objects] == ["ripe", "ripe", "turning"]
    np.testing.assert_array_equal(objects[0].mask, mask)
    np.testing.assert_array_equal(objects[1].mask, mask)
    assert 250 < objects[2].mask.sum() < 400  # the ellipse in a 20 x 20 box


@pytest.mark.parametrize(
    ("name", "stage"),
    [("berry_ripe", "ripe"), ("berry_unripe", "unripe"), ("berry_turning", "turning"),
     ("Cane", "cane"), ("red", "unripe"), ("blackberry", "fruit"), ("leaf", None)],
)  # fmt: skip
def test_category_names_say_the_stage(name: str, stage: str | None) -> None:
    assert stage_of(name) == stage


def test_train_without_the_extra_is_one_line_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    real = importlib.util.find_spec
    # train's require_train_extra looks the modules up through importlib.util.find_spec.
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda n, *a: None if n == "jax" else real(n, *a)
    )
    out = tmp_path / "w.onnx"
    assert main(["detector", "train", "--data", str(tmp_path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "softarm[train]" in err[0]
    assert not out.exists()


def _softarm(*args: str) -> subprocess.CompletedProcess[str]:
    return in_child("import sys; from softarm.cli import main; sys.exit(main(sys.argv[1:]))", *args)


@NEEDS_JAX
def test_onnx_export_round_trips_the_parameters(tmp_path: Path) -> None:
    done = in_child(
        """
        import sys
        import numpy as np
        from softarm.perception.detector.train.onnx_export import export_onnx, params_from_onnx
        from softarm.perception.detector.train.unet import init_params

        params = init_params(3)
        export_onnx(params, sys.argv[1])
        back = params_from_onnx(sys.argv[1])
        for name, (w, b) in params.items():
            np.testing.assert_array_equal(np.asarray(back[name][0]), np.asarray(w))
            np.testing.assert_array_equal(np.asarray(back[name][1]), np.asarray(b))
        """,
        str(tmp_path / "w.onnx"),
    )
    assert done.returncode == 0, done.stderr


@NEEDS_JAX
def test_a_network_of_other_widths_round_trips_and_bad_widths_are_refused(
    tmp_path: Path,
) -> None:
    done = in_child(
        """
        import sys
        import numpy as np
        from softarm.errors import InputError
        from softarm.perception.detector.train.onnx_export import export_onnx, params_from_onnx
        from softarm.perception.detector.train.unet import init_params, layers, widths_of

        params = init_params(3, (4, 6, 8, 10))
        export_onnx(params, sys.argv[1])
        back = params_from_onnx(sys.argv[1])
        assert widths_of(back) == (4, 6, 8, 10), widths_of(back)
        np.testing.assert_array_equal(np.asarray(back["dec3"][0]), np.asarray(params["dec3"][0]))
        for bad in [(8, 16, 24), (8, 16, 0, 32), (8, 16, 24.0, 32)]:
            try:
                layers(bad)
            except InputError as exc:
                assert "widths" in str(exc)
            else:
                raise AssertionError(bad)
        """,
        str(tmp_path / "w.onnx"),
    )
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize(
    ("option", "value"),
    [("--widths", "8,16,24"), ("--widths", "8,16,0,32"), ("--widths", "8,a,24,32"),
     ("--scale", "1.0"), ("--scale", "0,2"), ("--scale", "1,nan")],
)  # fmt: skip
def test_bad_widths_or_scale_are_one_usage_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, value: str
) -> None:
    args = ["detector", "train", "--data", str(tmp_path), "--out", str(tmp_path / "w.onnx")]
    with pytest.raises(SystemExit) as exit_info:
        main([*args, option, value])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert option in err[-1] and value in err[-1] and "Traceback" not in "".join(err)


@NEEDS_JAX
def test_crops_are_the_same_for_the_same_seed(tmp_path: Path) -> None:
    write_folder(tmp_path, training_scenes(3, seed=1))
    done = in_child(
        """
        import sys
        from pathlib import Path
        import numpy as np
        from softarm.perception.detector.train.augment import crop_batch
        from softarm.perception.detector.train.samples import load_samples

        samples, _ = load_samples([Path(sys.argv[1])])
        a, b = (crop_batch(samples, np.array([0, 1, 2, 0]), 5, 2) for _ in range(2))
        c = crop_batch(samples, np.array([0, 1, 2, 0]), 6, 2)
        for x, y in zip(a, b, strict=True):
            np.testing.assert_array_equal(x, y)
        assert not np.array_equal(a[0], c[0])
        """,
        str(tmp_path),
    )
    assert done.returncode == 0, done.stderr


@NEEDS_JAX
def test_train_end_to_end_on_a_tiny_dataset(tmp_path: Path) -> None:
    from softarm.perception.detector.learned import LearnedDetector
    from softarm.vision.camera_model import CameraModel

    data = tmp_path / "data"
    write_folder(data, training_scenes(6, seed=2))
    out = tmp_path / "w.onnx"
    args = ["detector", "train", "--data", str(data), "--out", str(out), "--epochs", "1"]
    done = _softarm(*args, "--seed", "3", "--widths", "4,6,8,10", "--scale", "1,2", "-q")
    assert done.returncode == 0, done.stderr
    assert "detector train: 1 epochs" in done.stdout
    record = json.loads(out.with_suffix(".json").read_text())
    assert record["epochs"] == 1 and record["seed"] == 3 and len(record["losses"]) == 1
    assert record["widths"] == [4, 6, 8, 10] and record["scale"] == [1.0, 2.0]
    assert np.isfinite(record["losses"][0])
    dets = LearnedDetector(out).detect_berries(
        np.zeros((H, W, 3), np.uint8), CameraModel.ideal(100.0, W, H)
    )
    assert isinstance(dets, list)


@NEEDS_JAX
def test_widths_with_a_network_to_fine_tune_are_one_line(tmp_path: Path) -> None:
    data = tmp_path / "data"
    write_folder(data, training_scenes(1, seed=2))
    args = ["detector", "train", "--data", str(data), "--out", str(tmp_path / "w.onnx")]
    done = _softarm(*args, "--from", "default", "--widths", "8,16,24,32")
    assert done.returncode == 2
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and "widths" in err[0]


@NEEDS_JAX
def test_train_from_a_file_that_is_no_network_is_one_line(tmp_path: Path) -> None:
    data = tmp_path / "data"
    write_folder(data, training_scenes(1, seed=2))
    (tmp_path / "bad.onnx").write_bytes(b"nonsense")
    args = ["detector", "train", "--data", str(data), "--out", str(tmp_path / "w.onnx")]
    done = _softarm(*args, "--from", str(tmp_path / "bad.onnx"))
    assert done.returncode == 2
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and "bad.onnx" in err[0]


@NEEDS_JAX
def test_a_stem_network_runs_in_opencv_as_in_jax_at_half_size(tmp_path: Path) -> None:
    done = in_child(
        """
        import sys
        import cv2
        import jax.numpy as jnp
        import numpy as np
        from softarm.perception.detector.network import RUN_SIDE, Network, normalise
        from softarm.perception.detector.train.onnx_export import export_onnx, params_from_onnx
        from softarm.perception.detector.train.unet import apply, init_params, stem_of

        params = init_params(4, (4, 6, 8, 10), stem=True)
        export_onnx(params, sys.argv[1])
        assert stem_of(params_from_onnx(sys.argv[1])) and not stem_of(init_params(4))
        image = np.random.default_rng(0).integers(0, 256, (48, 64, 3), np.uint8)
        x = normalise(image)
        jax_out = np.asarray(apply(params, jnp.asarray(x[None])))[0]
        net = cv2.dnn.readNetFromONNX(sys.argv[1])
        net.setInput(np.ascontiguousarray(x.transpose(2, 0, 1)[None]))
        cv_out = net.forward()[0].transpose(1, 2, 0)
        assert jax_out.shape == cv_out.shape == (24, 32, 6), (jax_out.shape, cv_out.shape)
        np.testing.assert_allclose(cv_out, jax_out, atol=1e-4)
        network = Network(sys.argv[1])
        assert network.stride == 2 and network.max_side == 2 * RUN_SIDE
        out = network.run(np.zeros((720, 1280, 3), np.uint8))
        assert out.probabilities.shape == (360, 640, 6 - 1) and out.size == (1280, 720)
        odd = network.run(np.zeros((101, 75, 3), np.uint8))
        assert odd.probabilities.shape[:2] == (51, 38)
        assert odd.upsample(odd.centres).shape == (101, 75)
        """,
        str(tmp_path / "w.onnx"),
    )
    assert done.returncode == 0, done.stderr


@NEEDS_JAX
def test_train_a_stem_network_on_zoomed_renders_end_to_end(tmp_path: Path) -> None:
    from softarm.perception.detector.learned import LearnedDetector
    from softarm.vision.camera_model import CameraModel

    data = tmp_path / "data"
    write_folder(data, training_scenes(4, seed=2))
    out = tmp_path / "w.onnx"
    args = ["detector", "train", "--data", str(data), "--out", str(out), "--epochs", "1"]
    done = _softarm(*args, "--widths", "4,6,8,10", "--stem", "--zoom", "2", "-q")
    assert done.returncode == 0, done.stderr
    record = json.loads(out.with_suffix(".json").read_text())
    assert record["stem"] is True and "zoom 2" in record["data"][0]
    det = LearnedDetector(out)
    assert det.network.stride == 2 and det.network.max_side == 1280
    assert isinstance(
        det.detect_berries(np.zeros((H, W, 3), np.uint8), CameraModel.ideal(100.0, W, H)), list
    )


@NEEDS_JAX
@pytest.mark.parametrize(
    ("extra", "word"),
    [(["--zoom", "2", "--zoom", "1"], "zoom"), (["--zoom", "0"], "zoom"),
     (["--from", "default", "--stem"], "stem")],
)  # fmt: skip
def test_zooms_not_one_per_folder_or_a_stem_to_fine_tune_are_one_line(
    tmp_path: Path, extra: list[str], word: str
) -> None:
    data = tmp_path / "data"
    write_folder(data, training_scenes(1, seed=2))
    args = ["detector", "train", "--data", str(data), "--out", str(tmp_path / "w.onnx")]
    done = _softarm(*args, *extra)
    assert done.returncode == 2, done.stderr
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and word in err[0], err
    assert not (tmp_path / "w.onnx").exists()
