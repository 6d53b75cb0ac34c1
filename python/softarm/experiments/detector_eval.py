"""The berry detectors side by side, per condition: every detector of
:data:`~softarm.perception.detector.choice.DETECTORS` (and optionally a candidate
network file, ``--weights``, scored as ``cand`` beside the shipped one) on each
labelled folder (``softarm dataset`` output), and ``colour+depth`` and
``net+colour+depth``, the same detectors given the folder's depth images (``depth/``),
scored as ``softarm detector evaluate`` scores; the figures written as JSON
(docs/data/detector_eval.json) and printed as the table of docs/perception.md ("The
learned detector").

    python -m softarm.experiments.detector_eval NAME=FOLDER ... --out docs/data/detector_eval.json

Each NAME=FOLDER is one condition (a look of the row, held out or not, the bush); the
time per image is the detector's alone (one OpenCV thread, median over the folder).
``--split-touching`` runs every detector with touching fruit split at the necks of their
distance map (:data:`SPLIT`; docs/data/detector_eval_touching.json). ``--raw-candidate``
adds the candidate decoded without its heatmap's fragment rule
(:mod:`softarm.perception.detector.fragments`) beside it
(docs/data/detector_eval_fragments*.json). ``--split-by-size`` adds each ``+depth``
candidate with merged fruit split by the size depth expects
(:mod:`softarm.perception.detector.size_split`) as ``...+depth+size`` rows, in the same
run (docs/data/detector_eval_size_split.json)."""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Sequence
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from softarm.perception.berries import DetectorSettings
from softarm.perception.detector.choice import DETECTORS, BerryDetector, detector
from softarm.perception.detector.evaluate import evaluate
from softarm.perception.detector.fragments import FRAGMENT_RULES, without_rules
from softarm.perception.detector.learned import ConfirmedDetector, LearnedDetector
from softarm.perception.detector.misses import fruit_cases, miss_table
from softarm.perception.detector.network import STRIDE, boundary_of, distance_of, heatmap_of

__all__ = [
    "CANDIDATE",
    "RAW",
    "SIZE",
    "SPLIT",
    "WITH_DEPTH",
    "candidates",
    "main",
    "run",
    "table",
]

_SHOWN = ("precision", "ripe_precision", "recall_ripe", "recall", "stage_right")


class _Timed:
    """A detector that keeps the time of each call, run with ``settings`` (None: each
    call's own)."""

    def __init__(self, inner: BerryDetector, settings: DetectorSettings | None = None) -> None:
        self.inner = inner
        self.settings = settings
        self.seconds: list[float] = []

    def detect_berries(
        self, image: Any, camera: Any, depth: Any = None, settings: Any = None
    ) -> Any:
        start = time.perf_counter()
        out = self.inner.detect_berries(image, camera, depth, self.settings or settings)
        self.seconds.append(time.perf_counter() - start)
        return out

    def fruit_mask(self, image: Any, settings: Any = None) -> Any:
        return self.inner.fruit_mask(image, settings)


#: The candidates: each detector of the harvest's choice on the colour image alone, and
#: two of them with the frame's depth as a check (:mod:`~softarm.perception.detector.depth_check`).
WITH_DEPTH = ("colour", "net+colour")
#: The prefix of a candidate network's rows (``--weights``), scored beside the shipped one.
CANDIDATE = "cand"


def _detectors(weights: Path | None, max_side: int | None) -> dict[str, BerryDetector]:
    dets = {name: detector(name) for name in DETECTORS}
    if weights is not None:
        dets[CANDIDATE] = LearnedDetector(weights, max_side)
        dets[f"{CANDIDATE}+colour"] = ConfirmedDetector(weights, max_side)
    return dets


def candidates(
    weights: Path | None = None, max_side: int | None = None
) -> dict[str, tuple[BerryDetector, bool]]:
    """{name: (detector, given depth)}: every detector without depth, then
    ``colour+depth`` and ``net+colour+depth``; with ``weights``, that network (run at
    ``max_side``, None: the network's own) as ``cand`` and ``cand+colour``, and
    ``cand+colour+depth``."""
    dets = _detectors(weights, max_side)
    out = {name: (det, False) for name, det in dets.items()}
    with_depth = (*WITH_DEPTH, f"{CANDIDATE}+colour") if weights is not None else WITH_DEPTH
    out.update({f"{name}+depth": (dets[name], True) for name in with_depth})
    return out


#: The detectors' settings with touching fruit split at the necks of their distance map
#: (:mod:`~softarm.perception.detector.touching`), the network's instances and the colour
#: rule's ripe blobs: ``--split-touching``.
SPLIT = DetectorSettings(split_touching=True, split_colour_blobs=True)


#: The prefix of the candidate's rows decoded without its heatmap's fragment rule
#: (``--raw-candidate``: :func:`softarm.perception.detector.fragments.without_rules`).
RAW = "cand-raw"


#: The suffix of a ``+depth`` candidate's rows with merged fruit split by the size depth
#: expects (``--split-by-size``: ``DetectorSettings.split_by_size`` for the network's
#: instances, ``split_colour_by_size`` for the colour rule's blobs).
SIZE = "+size"


def _figures(
    det: BerryDetector, folder: Path, with_depth: bool, settings: DetectorSettings | None
) -> dict[str, Any]:
    timed = _Timed(det, settings)
    depth = folder / "depth" if with_depth else None
    figures = evaluate(timed, folder / "annotations.json", folder, depth)
    figures.pop("per_image")
    figures["ms_per_image"] = round(1000.0 * float(np.median(timed.seconds)), 1)
    return figures


def run(
    conditions: dict[str, Path],
    weights: Path | None = None,
    max_side: int | None = None,
    settings: DetectorSettings | None = None,
    raw: bool = False,
    size: bool = False,
) -> dict[str, Any]:
    """{condition: {candidate: figures}} with ``ms_per_image``; a ``+depth`` candidate
    reads each folder's ``depth/``; every detector run with ``settings`` (None: the
    default); with ``raw`` and ``weights``, the candidate alone and with both checks
    also without the fragment rule (rows :data:`RAW` and ``RAW+colour+depth``); with
    ``size``, every ``+depth`` candidate also with ``split_by_size`` and
    ``split_colour_by_size`` (rows ``...+depth`` :data:`SIZE`)."""
    cv2.setNumThreads(1)
    out: dict[str, Any] = {}
    for name, folder in conditions.items():
        dets = candidates(weights, max_side)
        out[name] = {
            cand: _figures(det, folder, with_depth, settings)
            for cand, (det, with_depth) in dets.items()
        }
        if raw and weights is not None:
            with without_rules():
                for cand in (CANDIDATE, f"{CANDIDATE}+colour+depth"):
                    det, with_depth = dets[cand]
                    row = RAW + cand[len(CANDIDATE) :]
                    out[name][row] = _figures(det, folder, with_depth, settings)
        if size:
            base = settings or DetectorSettings()
            sized = replace(base, split_by_size=True, split_colour_by_size=True)
            for cand, (det, with_depth) in dets.items():
                if with_depth:
                    out[name][cand + SIZE] = _figures(det, folder, True, sized)
    return out


def _cell(value: object) -> str:
    return "–" if value is None else f"{value:.3f}" if isinstance(value, float) else str(value)


def table(results: dict[str, Any]) -> str:
    """A markdown table: one row per condition and candidate (loc. mm: the median
    distance of a matched detection's position from the fruit's, where depth was given)."""
    head = (
        "| condition | detector | " + " | ".join(_SHOWN) + " | ripe counted | loc. mm | ms/image |"
    )
    lines = [head, "|" + " --- |" * (len(_SHOWN) + 5)]
    for condition, by_detector in results.items():
        for det_name, f in by_detector.items():
            cells = " | ".join(_cell(f[k]) for k in _SHOWN)
            ripe = f["fruit_counted"]["ripe"]
            loc = _cell((f.get("localisation_mm") or {}).get("median"))
            ms = f["ms_per_image"]
            lines.append(f"| {condition} | {det_name} | {cells} | {ripe} | {loc} | {ms} |")
    return "\n".join(lines)


def _rule(weights: Path) -> dict[str, Any] | None:
    rule = FRAGMENT_RULES.get(heatmap_of(weights))
    return None if rule is None else asdict(rule)


def main(argv: Sequence[str] | None = None) -> None:
    """python -m softarm.experiments.detector_eval NAME=FOLDER ... [--weights W
    [--max-side N]] [--out F | --misses]."""
    p = argparse.ArgumentParser(prog="python -m softarm.experiments.detector_eval")
    p.add_argument("conditions", nargs="+", help="NAME=FOLDER (softarm dataset output)")
    p.add_argument(
        "--weights", type=Path, help="a candidate network, scored beside the shipped one"
    )
    p.add_argument(
        "--max-side", type=int,
        help="longer side (px) the candidate sees an image at (default: the network's own, "
        "640 px for a plain one, 1280 for one with the stem)",
    )  # fmt: skip
    p.add_argument(
        "--split-touching", action="store_true",
        help="split touching fruit at the necks of their distance map (the network's "
        "instances and the colour rule's ripe blobs), not the default",
    )  # fmt: skip
    p.add_argument(
        "--raw-candidate", action="store_true",
        help="also score the candidate (alone and with both checks) without its heatmap's "
        f"fragment rule, as {RAW} rows",
    )  # fmt: skip
    p.add_argument(
        "--split-by-size", action="store_true",
        help="also score each +depth candidate with merged fruit split by the size its "
        f"depth expects, as ...+depth{SIZE} rows",
    )  # fmt: skip
    p.add_argument("--note", default="", help="a line stored with the figures")
    p.add_argument("--out", type=Path, help="JSON file for the figures")
    p.add_argument(
        "--misses", action="store_true",
        help="instead: the ripe fruit the network (the candidate, else the shipped one) "
        "misses in all the folders together, binned by what might explain it",
    )  # fmt: skip
    a = p.parse_args(argv)
    conditions = {}
    for item in a.conditions:
        name, _, folder = item.partition("=")
        if not folder:
            p.error(f"{item!r}: expected NAME=FOLDER")
        conditions[name] = Path(folder)
    if a.max_side is not None and a.max_side < STRIDE:
        p.error(f"--max-side must be at least {STRIDE}, got {a.max_side}")
    settings = SPLIT if a.split_touching else None
    if a.misses:
        learned = LearnedDetector() if a.weights is None else LearnedDetector(a.weights, a.max_side)
        net = _Timed(learned, settings)
        cv2.setNumThreads(1)
        print(miss_table([c for f in conditions.values() for c in fruit_cases(net, f)]))
        return
    results = run(conditions, a.weights, a.max_side, settings, a.raw_candidate, a.split_by_size)
    print(table(results))
    if a.out is not None:
        doc = {
            "note": a.note,
            "folders": {k: str(v) for k, v in conditions.items()},
            "split_touching": a.split_touching,
            "split_by_size": a.split_by_size,
            # how the candidate's heatmap was trained decides how its peaks are read
            "candidate_heatmap": None if a.weights is None else heatmap_of(a.weights),
            # and the rule that tells its fragments from fruit (None: it has none)
            "candidate_fragment_rule": None if a.weights is None else _rule(a.weights),
            # and whether it cuts touching fruit apart by its boundary class
            "candidate_boundary": None if a.weights is None else boundary_of(a.weights),
            # and whether it splits them by a watershed of its distance to the fruit's edge
            "candidate_distance": None if a.weights is None else distance_of(a.weights),
            "results": results,
        }
        a.out.write_text(json.dumps(doc, indent=1) + "\n")


if __name__ == "__main__":
    main()
