"""Fruit that touch, split at the necks of their blob's distance map
(softarm.perception.detector.touching): for the colour rule's ripe blobs and the
network's instances, and never a lone fruit."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from detector_scenes import H, W, disc, draw, write_folder

from softarm.experiments.detector_eval import run
from softarm.perception.berries import DetectorSettings, detect_berries
from softarm.perception.detector.instances import instances
from softarm.perception.detector.network import CLASSES, NetworkOutput
from softarm.perception.detector.touching import NECK, _distance, disc_seeds, split_discs
from softarm.vision.camera_model import CameraModel

CAMERA = CameraModel.ideal(600.0, W, H)
#: The split is an option (off by default: docs/perception-candidates.md, "Splitting touching
#: fruit").
SPLIT = DetectorSettings(split_touching=True, split_colour_blobs=True)


def _ellipse(cx: int, cy: int, a: float, b: float) -> np.ndarray:
    yy, xx = np.mgrid[:H, :W]
    return np.asarray(((xx - cx) / a) ** 2 + ((yy - cy) / b) ** 2 <= 1.0)


@pytest.mark.parametrize("spacing", [18, 15])  # just touching; a sixth of a width hidden
def test_two_touching_discs_give_two_seeds_at_their_centres(spacing: int) -> None:
    blob = disc(60, 60, 9) | disc(60 + spacing, 60, 9)
    seeds = disc_seeds(blob, 2.5)
    assert len(seeds) == 2
    cols = sorted(c for _, c, _ in seeds)
    assert abs(cols[0] - 60) <= 1.5 and abs(cols[1] - 60 - spacing) <= 1.5
    left, right = sorted(split_discs(blob, seeds), key=lambda m: np.nonzero(m)[1].mean())
    assert not (left & right).any() and ((left | right) == blob).all()
    assert abs(int(left.sum()) - int(right.sum())) < 0.1 * blob.sum()


def test_a_small_fruit_touching_a_large_one_is_cut_at_the_contact() -> None:
    big, small = disc(60, 60, 12), disc(80, 60, 7)  # touching: 12 + 7 < 20
    seeds = disc_seeds(big | small, 2.5)
    pieces = sorted(split_discs(big | small, seeds), key=lambda m: -int(m.sum()))
    # The weighted nearest seed gives the big fruit all of its disc; the plain nearest
    # seed would have cut it at the midpoint of the two centres (column 70).
    assert len(pieces) == 2 and (pieces[0] & big).sum() >= 0.97 * big.sum()


@pytest.mark.parametrize(
    "blob",
    [
        disc(60, 60, 10),
        _ellipse(60, 60, 13, 9),  # an elongated fruit: one peak
        disc(60, 60, 10) | disc(70, 60, 3),  # a bump on the outline
        disc(60, 60, 10) | disc(60 + 7, 60, 9),  # two discs that overlap deeply: one fruit
    ],
)
def test_one_fruit_gives_one_seed(blob: np.ndarray) -> None:
    assert len(disc_seeds(blob, 2.5)) == 1
    assert len(split_discs(blob, disc_seeds(blob, 2.5))) == 1


def test_the_neck_rule_follows_the_geometry_of_two_discs() -> None:
    # Two discs of radius r, centres d apart: saddle sqrt(r^2 - d^2/4); split when it is
    # below NECK * r, i.e. d > 2 r sqrt(1 - NECK^2).
    r = 20
    threshold = 2 * r * np.sqrt(1 - NECK**2)
    for d, split in ((threshold - 4, False), (threshold + 4, True)):
        blob = disc(50, 60, r) | disc(50 + round(d), 60, r)
        assert (len(disc_seeds(blob, 2.5)) == 2) is split, d


def test_an_empty_blob_has_no_seed() -> None:
    assert disc_seeds(np.zeros((5, 5), bool), 2.5) == []


def test_two_touching_ripe_fruit_are_two_detections_and_a_lone_one_stays_one() -> None:
    a, b, lone = disc(50, 60, 9), disc(68, 60, 9), disc(120, 60, 9)
    image = draw([("ripe", a), ("ripe", b), ("ripe", lone)])
    found = detect_berries(image, CAMERA, settings=SPLIT)
    assert len(found) == 3 and all(d.ripeness == "ripe" for d in found)
    xs = sorted(d.center[0] for d in found)
    assert abs(xs[0] - 50) < 2 and abs(xs[1] - 68) < 2 and abs(xs[2] - 120) < 1
    # Without the split the pair is one blob: one detection over both fruit.
    assert len(detect_berries(image, CAMERA)) == 2  # the default, and the split turned off


def test_a_row_of_three_touching_fruit_is_three_detections() -> None:
    fruit = [("ripe", disc(40 + 18 * k, 60, 9)) for k in range(3)]
    assert len(detect_berries(draw(fruit), CAMERA, settings=SPLIT)) == 3
    # Whole, the row is too elongated for a fruit: nothing is found without the split.
    assert detect_berries(draw(fruit), CAMERA) == []


def _output(fruit: np.ndarray) -> NetworkOutput:
    """A ripe-everywhere network output on ``fruit`` with a flat centre heatmap (no peak
    reaches the heatmap's threshold)."""
    probs = np.zeros((*fruit.shape, len(CLASSES)), np.float32)
    probs[..., 0] = ~fruit
    probs[..., 1] = fruit
    return NetworkOutput(probs, np.full(fruit.shape, 0.3, np.float32), (2 * W, 2 * H))


def test_the_network_s_touching_fruit_split_without_the_heatmap() -> None:
    a, b, lone = disc(40, 50, 9), disc(57, 50, 9), disc(110, 50, 9)
    camera = CameraModel.ideal(600.0, 2 * W, 2 * H)
    found = instances(_output(a | b | lone), camera, None, SPLIT)
    assert len(found) == 3
    xs = sorted(d.center[0] for d in found)
    assert abs(xs[0] - 80.5) < 3 and abs(xs[1] - 114.5) < 3 and abs(xs[2] - 220.5) < 2
    # The default splits at the heatmap's peaks, and this heatmap has none.
    assert len(instances(_output(a | b | lone), camera, None, DetectorSettings())) == 2


def test_the_evaluation_scores_the_split_as_an_option(tmp_path: Path) -> None:
    scene = [("ripe", disc(50, 60, 9), True), ("ripe", disc(68, 60, 9), True),
             ("ripe", disc(120, 60, 9), True)]  # fmt: skip
    write_folder(tmp_path, [scene])
    whole = run({"drawn": tmp_path})["drawn"]["colour"]
    split = run({"drawn": tmp_path}, settings=SPLIT)["drawn"]["colour"]
    assert whole["recall_ripe"] == pytest.approx(2 / 3, abs=1e-3)  # the pair: one matched
    assert split["recall_ripe"] == 1.0 and split["precision"] == 1.0


def test_the_distance_map_is_exact_so_peaks_do_not_change_from_run_to_run() -> None:
    # OpenCV's float distance differs in its last bit with the buffer's alignment, which
    # flipped ties between neighbouring peaks from one run to the next: each value must be
    # the correctly rounded root of the integer squared distance, whatever the buffer.
    yy, xx = np.mgrid[:60, :90]  # a size at which OpenCV's last bits were seen to vary
    blob = ((xx - 30) ** 2 + (yy - 30) ** 2 <= 400) | ((xx - 60) ** 2 + (yy - 30) ** 2 <= 400)
    for offset in range(4):
        buffer = np.zeros(blob.size + offset, bool)
        shifted = buffer[offset:].reshape(blob.shape)
        shifted[:] = blob
        d = _distance(shifted)
        exact = np.sqrt(np.rint(d.astype(np.float64) ** 2)).astype(np.float32)
        assert np.array_equal(d, exact)
        assert disc_seeds(shifted, 2.5) == disc_seeds(blob, 2.5)


def test_detect_and_evaluate_split_touching_fruit_on_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from softarm.cli import main

    pair = [("ripe", disc(50, 60, 9), True), ("ripe", disc(68, 60, 9), True)]
    labels = write_folder(tmp_path, [pair])
    image = next((tmp_path / "images").iterdir())
    counts = []
    for extra in ([], ["--split-touching"]):
        assert main(["detect", str(image), "--detector", "colour", *extra]) == 0
        counts.append(capsys.readouterr().out.strip().splitlines()[-1])
        args = ["detector", "evaluate", "--images", str(tmp_path / "images")]
        assert main([*args, "--labels", str(labels), "--detector", "colour", "-q", *extra]) == 0
        shown = capsys.readouterr().out.split("\ndetector evaluate")[0]
        counts.append(str(json.loads(shown)["recall_ripe"]))
    assert counts[0].startswith("detect: 1 berries") and counts[1] == "0.5"
    assert counts[2].startswith("detect: 2 berries") and counts[3] == "1.0"
