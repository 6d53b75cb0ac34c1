"""Merged fruit split by the size depth expects (softarm.perception.detector.size_split):
a pair of touching fruit at a known depth, one blob too large for one fruit, becomes two
detections at their centres (the colour rule's blobs and the network's instances); a
lone elongated fruit is never split; the option off leaves every result as it was."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from detector_scenes import H, W, disc, draw, sphere_depth, write_folder

from softarm.experiments.detector_eval import SIZE, run
from softarm.perception.berries import DetectorSettings, detect_berries
from softarm.perception.detector.depth_check import (
    FRUIT_RADIUS_M,
    DepthCheck,
    metric_radius,
    rejection,
)
from softarm.perception.detector.instances import instances
from softarm.perception.detector.network import CLASSES, NetworkOutput
from softarm.perception.detector.size_split import SizeSplit, apparent_radius, lloyd_pieces
from softarm.vision.camera_model import CameraModel

FOCAL = 300.0
CAMERA = CameraModel.ideal(FOCAL, W, H)
SIZE_SPLIT = DetectorSettings(split_by_size=True, split_colour_by_size=True)
SURFACE = 0.3  # m: a 13 px outline there is a 13 mm fruit


def _pair() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two touching 13 mm fruit (13 px at 0.3 m through f = 300 px, centres (50, 60)
    and (76, 60)), their depth, and the two discs' union."""
    a, b = disc(50, 60, 13), disc(76, 60, 13)
    depth = np.minimum(
        sphere_depth(50, 60, 13, SURFACE, FOCAL), sphere_depth(76, 60, 13, SURFACE, FOCAL)
    )
    return draw([("ripe", a), ("ripe", b)]), depth, a | b


def _ellipse(cx: int, cy: int, a: float, b: float) -> np.ndarray:
    yy, xx = np.mgrid[:H, :W]
    return np.asarray(((xx - cx) / a) ** 2 + ((yy - cy) / b) ** 2 <= 1.0)


def test_the_apparent_radius_inverts_the_metric_radius() -> None:
    for radius_m, surface in ((0.009, 0.06), (0.0154, 0.3), (0.012, 2.5)):
        r_px = apparent_radius(radius_m, surface, FOCAL)
        assert metric_radius(r_px, surface, FOCAL) == pytest.approx(radius_m, rel=1e-9)


def test_a_pair_of_touching_fruit_is_two_detections_at_their_centres() -> None:
    image, depth, union = _pair()
    # The pair's equivalent radius (18.4 px, 18 mm) is over the largest fruit's bound:
    # the depth check drops it whole.
    radius = float(np.sqrt(union.sum() / np.pi))
    assert rejection(union, radius, depth, FOCAL, DepthCheck()) == "size"
    assert detect_berries(image, CAMERA, depth) == []
    found = detect_berries(image, CAMERA, depth, SIZE_SPLIT)
    assert len(found) == 2 and all(d.ripeness == "ripe" for d in found)
    (xa, ya), (xb, yb) = sorted(d.center for d in found)
    assert abs(xa - 50) <= 1 and abs(xb - 76) <= 1 and abs(ya - 60) <= 1 and abs(yb - 60) <= 1
    assert all(d.position is not None for d in found)


def test_each_detector_has_its_own_switch() -> None:
    image, depth, _ = _pair()
    # split_by_size is the network's instances', split_colour_by_size the colour rule's.
    assert detect_berries(image, CAMERA, depth, DetectorSettings(split_by_size=True)) == []
    colour_only = DetectorSettings(split_colour_by_size=True)
    assert len(detect_berries(image, CAMERA, depth, colour_only)) == 2


def test_a_row_of_three_fruit_is_three_detections() -> None:
    fruit = [disc(30 + 22 * k, 60, 11) for k in range(3)]
    depth = np.min([sphere_depth(30 + 22 * k, 60, 11, SURFACE, FOCAL) for k in range(3)], axis=0)
    image = draw([("ripe", m) for m in fruit])
    xs = sorted(d.center[0] for d in detect_berries(image, CAMERA, depth, SIZE_SPLIT))
    assert len(xs) == 3 and all(abs(x - (30 + 22 * k)) <= 1.5 for k, x in enumerate(xs))


def test_a_lone_elongated_fruit_is_not_split() -> None:
    # The largest fruit seen from its side: half-width 12.9 mm, half-length 15.4 mm (the
    # check's radius bound), at 0.3 m: an ellipse of about 12.3 x 14.7 px.
    a = apparent_radius(0.0129, SURFACE, FOCAL)
    b = apparent_radius(FRUIT_RADIUS_M[1], SURFACE, FOCAL)
    fruit = _ellipse(80, 60, b, a)
    depth = np.minimum(
        sphere_depth(80, 60, round(a), SURFACE, FOCAL), np.full((H, W), SURFACE + 0.2)
    )
    sizes = SizeSplit(depth, FOCAL, DepthCheck(), DepthCheck().outline_px)
    assert sizes.plan(fruit, 0, 0)[0] == 1
    found = detect_berries(draw([("ripe", fruit)]), CAMERA, depth, SIZE_SPLIT)
    assert len(found) == 1 and abs(found[0].center[0] - 80) < 1


def test_without_depth_nothing_is_split_and_a_far_patch_is_left_whole() -> None:
    image, _, union = _pair()
    with_option = detect_berries(image, CAMERA, None, SIZE_SPLIT)
    [whole] = detect_berries(image, CAMERA)
    assert len(with_option) == 1 and with_option[0].box == whole.box
    # The same blob 0.1 m away is 5 fruit's area or more: no cluster, left whole.
    near = SizeSplit(np.full((H, W), 0.1), FOCAL, DepthCheck(), 2.0)
    assert near.plan(union, 0, 0)[0] == 1


def test_lloyd_pieces_cover_the_blob_once() -> None:
    _, _, union = _pair()
    pieces = lloyd_pieces(union, 2)
    assert len(pieces) == 2 and not (pieces[0] & pieces[1]).any()
    assert ((pieces[0] | pieces[1]) == union).all()
    assert abs(int(pieces[0].sum()) - int(pieces[1].sum())) <= 0.05 * union.sum()


def _output(fruit: np.ndarray) -> NetworkOutput:
    """A ripe-everywhere network output on ``fruit`` (at half the image's size) with a
    flat centre heatmap: no peak splits it."""
    probs = np.zeros((*fruit.shape, len(CLASSES)), np.float32)
    probs[..., 0] = ~fruit
    probs[..., 1] = fruit
    return NetworkOutput(probs, np.full(fruit.shape, 0.3, np.float32), (2 * W, 2 * H))


def test_the_network_s_merged_instance_is_split_by_its_size() -> None:
    # The pair at half size on the network's grid; the image (and depth) at full size.
    small = disc(40, 50, 7) | disc(54, 50, 7)
    camera = CameraModel.ideal(FOCAL, 2 * W, 2 * H)  # 14 px image discs: 14 mm fruit
    yy, xx = np.mgrid[: 2 * H, : 2 * W]
    depth = np.full((2 * H, 2 * W), SURFACE + 0.2)
    for cx in (80.5, 108.5):
        rho = np.hypot(xx - cx, yy - 100.5) * SURFACE / FOCAL
        radius = 14 * SURFACE / FOCAL
        inside = rho <= radius
        depth[inside] = SURFACE + radius - np.sqrt(radius**2 - rho[inside] ** 2)
    assert instances(_output(small), camera, depth, DetectorSettings()) == []
    colour_only = DetectorSettings(split_colour_by_size=True)
    assert instances(_output(small), camera, depth, colour_only) == []
    found = instances(_output(small), camera, depth, SIZE_SPLIT)
    assert len(found) == 2
    xs = sorted(d.center[0] for d in found)
    assert abs(xs[0] - 80.5) <= 1.5 and abs(xs[1] - 108.5) <= 1.5


def test_the_option_off_leaves_the_results_as_they_were(tmp_path: Path) -> None:
    scene = [("ripe", disc(50, 60, 13), True), ("ripe", disc(76, 60, 13), True),
             ("ripe", disc(130, 60, 10), True)]  # fmt: skip
    write_folder(tmp_path, [scene])
    f = float(max(W, H))  # the evaluation's ideal camera for labels without one
    z = SURFACE * f / FOCAL  # the same fruit sizes through that camera
    d = np.minimum.reduce(
        [sphere_depth(50, 60, 13, z, f), sphere_depth(76, 60, 13, z, f),
         sphere_depth(130, 60, 10, z, f)]
    )  # fmt: skip
    (tmp_path / "depth").mkdir()
    np.save(tmp_path / "depth" / "000000.npy", d)
    rows = run({"drawn": tmp_path}, size=True)["drawn"]
    plain = run({"drawn": tmp_path})["drawn"]
    for name in ("colour+depth", "net+colour+depth"):
        base = {k: v for k, v in rows[name].items() if k != "ms_per_image"}
        assert base == {k: v for k, v in plain[name].items() if k != "ms_per_image"}
    assert rows["colour+depth"]["recall_ripe"] == pytest.approx(1 / 3, abs=1e-3)
    assert rows["colour+depth" + SIZE]["recall_ripe"] == 1.0
    assert rows["colour+depth" + SIZE]["precision"] == 1.0
