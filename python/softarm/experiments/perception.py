"""Perception measured on rendered bushes it was not tuned on: the berry detector and
the stereo localisation on C1 (docs/perception.md's tables come from here).

``--detector net --model FILE`` runs the same harness with the pixel network of
:mod:`softarm.perception.net_berries` in place of the colour thresholds (the stereo
matching and the blob stage unchanged); ``--compare --model FILE`` measures both on the
same bushes, with their time per C1 frame on one core (docs/perception.md, "Which
detector")."""

from __future__ import annotations

import argparse
import contextlib
import time
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from unittest import mock

import cv2
import numpy as np

import softarm
from softarm.harvest.rigs.sim.options import default_cameras
from softarm.perception import stereo as stereo_module
from softarm.perception.berries import BerryDetection
from softarm.perception.net_berries import NetDetector
from softarm.perception.stereo import locate_berries
from softarm.sim.bush import Bush
from softarm.sim.render.scoring import BerryScore, score_berries
from softarm.sim.render.world import world_for
from softarm.sim.rig_cameras import BASE_TAG_ID

__all__ = ["compare", "evaluate_berries", "pixel_stage"]

#: Timed runs of each detector per bush (alternated; the median is kept).
TIMING_REPEATS = 5


@contextlib.contextmanager
def pixel_stage(detector: NetDetector | None) -> Iterator[None]:
    """Within the block, :func:`locate_berries` finds its fruit pixels with
    ``detector``'s network (None: the colour thresholds, as always). Only the pixel
    stage changes: the blob and shape stage and the stereo matching are the same."""
    if detector is None:
        yield
        return
    with (
        mock.patch.object(stereo_module, "detect_berries", detector.detect_berries),
        mock.patch.object(stereo_module, "fruit_mask", detector.fruit_mask),
    ):
        yield


def evaluate_berries(
    seeds: Iterable[int],
    n_berries: int = 10,
    unripe_fraction: float = 0.4,
    detectors: Sequence[NetDetector | None] = (None,),
    repeats: int = 1,
) -> list[tuple[int, list[BerryScore]]]:
    """Render one bush per seed (no arm in view), run the stereo berry perception on C1
    with each of ``detectors`` (None: the colour-and-shape one), and score it; the time
    is that of :func:`locate_berries` alone, the median of ``repeats`` runs, the
    detectors alternated."""
    arm = softarm.SoftArm.blackberry()
    cams = default_cameras()
    out = []
    for seed in seeds:
        bush = Bush.generate(
            arm, n_berries, seed, view_point=cams.T_base_c1[:3, 3], unripe_fraction=unripe_fraction
        )
        world = world_for(bush, cams, BASE_TAG_ID)
        left, right = world.c1()
        times: list[list[float]] = [[] for _ in detectors]
        found: list[list[BerryDetection]] = []
        for _ in range(repeats):
            found = []
            for k, detector in enumerate(detectors):
                with pixel_stage(detector):
                    t0 = time.perf_counter()
                    dets = locate_berries(left.colour, right.colour, world.stereo)
                    times[k].append(time.perf_counter() - t0)
                found.append(dets)
        scores = []
        for dets, elapsed in zip(found, times, strict=True):
            score = score_berries(world, dets)
            score.seconds.append(float(np.median(elapsed)))
            scores.append(score)
        world.close()
        out.append((seed, scores))
    return out


HEADER = (
    "| bush | precision | recall | ripe/unripe right | ripe ≥ ½ visible | localised "
    "| median mm | p95 mm |"
)


def table(seeds: Iterable[int], detector: NetDetector | None = None) -> str:
    """A Markdown table of :func:`evaluate_berries` over ``seeds``, one row per bush and
    the pooled figures last."""
    rows = [HEADER, "|" + " --- |" * 8]
    pooled = BerryScore()
    for seed, (score,) in evaluate_berries(seeds, detectors=(detector,)):
        pooled.add(score)
        rows.append(_row(str(seed), score.summary()))
    rows.append(_row("**all**", pooled.summary()))
    return "\n".join(rows)


def compare(seeds: Iterable[int], net: NetDetector, names: Sequence[str]) -> str:
    """Both detectors on the same bushes: a table per detector and the pooled figures
    with the median time per C1 frame (one OpenCV thread)."""
    cv2.setNumThreads(1)
    results = evaluate_berries(seeds, detectors=(None, net), repeats=TIMING_REPEATS)
    parts = []
    pooled = [BerryScore(), BerryScore()]
    for k, name in enumerate(names):
        rows = [f"### {name}", "", HEADER, "|" + " --- |" * 8]
        for seed, scores in results:
            pooled[k].add(scores[k])
            rows.append(_row(str(seed), scores[k].summary()))
        rows.append(_row("**all**", pooled[k].summary()))
        parts.append("\n".join(rows))
    summary = [
        "### Pooled",
        "",
        "| detector | precision | recall | ripe/unripe right | ripe ≥ ½ visible | localised "
        "| median mm | p95 mm | ms per C1 frame (median) |",
        "|" + " --- |" * 9,
    ]
    for k, name in enumerate(names):
        s = pooled[k].summary()
        ms = 1000.0 * float(np.median(pooled[k].seconds))
        summary.append(_row(name, s) + f" {ms:.1f} |")
    return "\n\n".join(["\n".join(summary), *parts]) + "\n"


def _row(name: str, s: dict[str, float | tuple[float, float]]) -> str:
    return (
        f"| {name} | {s['precision']:.3f} | {s['recall']:.3f} | {s['ripeness_accuracy']:.3f} "
        f"| {s['ripe_in_view']} | {s['localised']} | {s['median_mm']:.2f} | {s['p95_mm']:.2f} |"
    )


def main(argv: Sequence[str] | None = None) -> None:
    """python -m softarm.experiments.perception FIRST LAST [--detector colour|net]
    [--model FILE] [--compare]."""
    p = argparse.ArgumentParser(prog="python -m softarm.experiments.perception")
    p.add_argument("first", type=int)
    p.add_argument("last", type=int)
    p.add_argument("--detector", choices=("colour", "net"), default="colour")
    p.add_argument("--model", type=Path, help="the pixel network (ONNX) for --detector net")
    p.add_argument("--compare", action="store_true", help="both detectors, with timings")
    a = p.parse_args(argv)
    seeds = range(a.first, a.last + 1)
    if (a.detector == "net" or a.compare) and a.model is None:
        p.error("--detector net and --compare need --model")
    net = NetDetector(a.model) if a.model is not None else None
    if a.compare:
        assert net is not None
        print(compare(seeds, net, ("colour-and-shape", f"pixel net ({a.model.name})")))
    else:
        print(table(seeds, net if a.detector == "net" else None))


if __name__ == "__main__":
    main()
