"""Fragments after the focal heatmap's split (softarm.perception.detector.fragments): one
fruit with two peaks joined by the heatmap is merged back, two touching fruit whose
heatmap falls between them stay two, a small weak speck is dropped, a small core grows
into the rim the network half saw, and the logistic heatmap's decoding is unchanged."""

from __future__ import annotations

import json
import shutil
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
from detector_scenes import H, W, disc, write_folder

from softarm.experiments.detector_eval import main
from softarm.perception.berries import DetectorSettings
from softarm.perception.detector.fragments import (
    FRAGMENT_RULES,
    FragmentRule,
    grown,
    merge_fragments,
    speck,
    without_rules,
)
from softarm.perception.detector.instances import instances
from softarm.perception.detector.network import CLASSES, DEFAULT_WEIGHTS, NetworkOutput
from softarm.perception.detector.touching import split_discs
from softarm.vision.camera_model import CameraModel

CAMERA = CameraModel.ideal(600.0, 2 * W, 2 * H)
FOCAL = FRAGMENT_RULES["focal"]


def _output(fruit: np.ndarray, centres: np.ndarray, heatmap: str) -> NetworkOutput:
    """A network output (at half the image's size) whose fruit pixels are ``fruit`` (all
    ripe) and whose centre heatmap is ``centres``."""
    probs = np.zeros((H, W, len(CLASSES)), np.float32)
    probs[..., 0] = ~fruit
    probs[..., 1] = fruit
    return NetworkOutput(probs, centres.astype(np.float32), (2 * W, 2 * H), heatmap)


def _bump(peaks: list[tuple[int, int]], sigma: float, height: float) -> np.ndarray:
    """A heatmap with a Gaussian of ``height`` at each of ``peaks`` (row, col), the
    largest value where they overlap."""
    yy, xx = np.mgrid[:H, :W]
    out = np.zeros((H, W), np.float32)
    for r, c in peaks:
        out = np.maximum(out, height * np.exp(-((yy - r) ** 2 + (xx - c) ** 2) / (2 * sigma**2)))
    return out


def _one_fruit_two_peaks() -> tuple[np.ndarray, np.ndarray]:
    """One disc (radius 8) whose heatmap has two tops 6 px apart on one ridge: the
    two halves of a turning fruit, as the focal network peaks on them."""
    fruit = disc(60, 50, 8)
    # two local maxima; the ridge between them 0.8 of their height
    ridge = _bump([(50, 57), (50, 63)], 4.5, 0.5)
    return fruit, ridge


def test_one_fruit_split_at_two_peaks_of_one_ridge_is_merged_back() -> None:
    fruit, centres = _one_fruit_two_peaks()
    dets = instances(_output(fruit, centres, "focal"), CAMERA, None, DetectorSettings())
    assert len(dets) == 1
    assert abs(dets[0].center[0] - 120) < 2 and abs(dets[0].center[1] - 100) < 2


def test_without_the_rule_the_same_fruit_is_two_fragments() -> None:
    fruit, centres = _one_fruit_two_peaks()
    rows, cols = (50, 50), (57, 63)
    peaks = list(zip(rows, cols, strict=True))
    pieces = split_discs(fruit, [(float(r), float(c), 0.0) for r, c in peaks])
    assert len(merge_fragments(pieces, peaks, centres, None)) == 2
    merged = merge_fragments(pieces, peaks, centres, FOCAL)
    assert len(merged) == 1 and np.array_equal(merged[0], fruit)


def test_two_touching_fruit_whose_heatmap_falls_between_them_stay_two() -> None:
    a, b = disc(52, 50, 7), disc(66, 50, 7)  # centres 14 px apart: they touch
    centres = _bump([(50, 52), (50, 66)], 1.5, 0.6)  # sharp peaks, ~0 at the contact
    dets = instances(_output(a | b, centres, "focal"), CAMERA, None, DetectorSettings())
    xs = sorted(d.center[0] for d in dets)
    assert len(dets) == 2 and abs(xs[0] - 104) < 3 and abs(xs[1] - 132) < 3, xs


def test_three_in_a_row_merge_only_the_pair_the_heatmap_joins() -> None:
    # a fruit of two tops (x 40 and 46) touching a second fruit with one peak at x 58
    fruit = disc(43, 50, 8) | disc(58, 50, 8)
    centres = np.maximum(_bump([(50, 40), (50, 46)], 4.5, 0.5), _bump([(50, 58)], 1.5, 0.6))
    dets = instances(_output(fruit, centres, "focal"), CAMERA, None, DetectorSettings())
    xs = sorted(d.center[0] for d in dets)
    assert len(dets) == 2 and abs(xs[0] - 86) < 5 and abs(xs[1] - 118) < 5, xs


def test_a_small_weak_speck_is_dropped_and_a_small_clear_fruit_kept() -> None:
    small = disc(30, 30, 2)  # 13 px: under the speck size
    assert 6 <= int(small.sum()) < FOCAL.speck_pixels
    weak = _bump([(30, 30)], 1.0, 0.9 * FOCAL.speck_peak)
    clear = _bump([(30, 30)], 1.0, 0.6)
    s = DetectorSettings()
    assert instances(_output(small, weak, "focal"), CAMERA, None, s) == []
    assert len(instances(_output(small, clear, "focal"), CAMERA, None, s)) == 1
    # a fruit of the speck size or more stays whatever its peak
    big = disc(30, 30, 4)
    assert int(big.sum()) >= FOCAL.speck_pixels
    assert len(instances(_output(big, _bump([(30, 30)], 1.0, 0.1), "focal"), CAMERA, None, s)) == 1


def test_the_logistic_heatmap_has_no_fragment_rule() -> None:
    assert "logistic" not in FRAGMENT_RULES
    small = disc(30, 30, 2)
    weak = _bump([(30, 30)], 1.0, 0.05)
    assert not speck(small, weak, None)
    dets = instances(_output(small, weak, "logistic"), CAMERA, None, DetectorSettings())
    assert len(dets) == 1  # the shipped network's decoding as before


def test_a_rule_without_a_saddle_or_a_speck_size_changes_nothing() -> None:
    fruit, centres = _one_fruit_two_peaks()
    peaks = [(50, 57), (50, 63)]
    pieces = split_discs(fruit, [(50.0, 57.0, 0.0), (50.0, 63.0, 0.0)])
    rule = FragmentRule(saddle=None)
    assert len(merge_fragments(pieces, peaks, centres, rule)) == 2
    assert not speck(disc(30, 30, 2), np.zeros((H, W), np.float32), rule)


def test_without_rules_restores_the_rules_even_after_an_error() -> None:
    before = dict(FRAGMENT_RULES)
    with pytest.raises(RuntimeError), without_rules():
        assert FRAGMENT_RULES == {}
        raise RuntimeError("inside")
    assert FRAGMENT_RULES == before


def test_the_harness_scores_the_candidate_with_and_without_the_rule(tmp_path: Path) -> None:
    weights = tmp_path / "focal.onnx"
    shutil.copy(DEFAULT_WEIGHTS, weights)
    weights.with_suffix(".json").write_text(json.dumps({"heatmap": "focal"}))
    scene = [("ripe", disc(50, 60, 9), True), ("unripe", disc(110, 60, 9), True)]
    folder = tmp_path / "scenes"
    write_folder(folder, [scene])
    out = tmp_path / "eval.json"
    main([f"drawn={folder}", "--weights", str(weights), "--raw-candidate", "--out", str(out)])
    doc = json.loads(out.read_text())
    rows = doc["results"]["drawn"]
    assert {"cand", "cand+colour+depth", "cand-raw", "cand-raw+colour+depth"} <= set(rows)
    assert doc["candidate_fragment_rule"] == asdict(FRAGMENT_RULES["focal"])
    assert FRAGMENT_RULES["focal"] == FOCAL  # the rule is back after the raw rows


def test_a_small_core_grows_into_the_fruit_rim_the_network_half_saw() -> None:
    core, whole = disc(30, 30, 2), disc(30, 30, 4)  # 13 px over 0.5; the rim at 0.4
    assert int(core.sum()) < FOCAL.grow_pixels and FOCAL.grow_low <= 0.4
    fruit = np.where(core, 0.9, np.where(whole, 0.4, 0.0)).astype(np.float32)
    taken = fruit > 0.5
    piece, x, y = grown(core[26:35, 26:35], 26, 26, fruit, taken, FOCAL)
    full = np.zeros((H, W), bool)
    full[y : y + piece.shape[0], x : x + piece.shape[1]] = piece
    assert np.array_equal(full, whole)  # the rim is 2 px: all of it, nothing beyond
    # no rule, or a piece of the growth size or more: unchanged
    assert grown(core[26:35, 26:35], 26, 26, fruit, taken, None)[0].sum() == core.sum()
    big = disc(30, 30, 4)[24:37, 24:37]
    assert int(big.sum()) >= FOCAL.grow_pixels
    assert grown(big, 24, 24, fruit, taken, FOCAL)[0] is big


def test_a_small_core_does_not_grow_into_another_fruit() -> None:
    core, rim = disc(30, 30, 2), disc(30, 30, 4)
    other = disc(36, 30, 3)  # another part's pixels, over the threshold, in the rim's way
    fruit = np.where(core | other, 0.9, np.where(rim, 0.4, 0.0)).astype(np.float32)
    piece, x, y = grown(core[26:35, 26:35], 26, 26, fruit, fruit > 0.5, FOCAL)
    full = np.zeros((H, W), bool)
    full[y : y + piece.shape[0], x : x + piece.shape[1]] = piece
    assert not (full & other).any() and (full & rim & ~core).any()
