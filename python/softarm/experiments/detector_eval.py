"""The berry detectors side by side, per condition: every detector of
:data:`~softarm.perception.detector.choice.DETECTORS` (and optionally a network file of
one's own) on each labelled folder (``softarm dataset`` output), scored as ``softarm
detector evaluate`` scores; the figures written as JSON (docs/data/detector_eval.json)
and printed as the table of docs/perception.md ("The learned detector").

    python -m softarm.experiments.detector_eval NAME=FOLDER ... --out docs/data/detector_eval.json

Each NAME=FOLDER is one condition (a look of the row, held out or not, the bush); the
time per image is the detector's alone (one OpenCV thread, median over the folder)."""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from softarm.perception.detector.choice import DETECTORS, BerryDetector, detector
from softarm.perception.detector.evaluate import evaluate
from softarm.perception.detector.learned import ConfirmedDetector, LearnedDetector

__all__ = ["main", "table"]

_SHOWN = ("precision", "ripe_precision", "recall_ripe", "recall", "stage_right")


class _Timed:
    """A detector that keeps the time of each call."""

    def __init__(self, inner: BerryDetector) -> None:
        self.inner = inner
        self.seconds: list[float] = []

    def detect_berries(
        self, image: Any, camera: Any, depth: Any = None, settings: Any = None
    ) -> Any:
        start = time.perf_counter()
        out = self.inner.detect_berries(image, camera, depth, settings)
        self.seconds.append(time.perf_counter() - start)
        return out

    def fruit_mask(self, image: Any, settings: Any = None) -> Any:
        return self.inner.fruit_mask(image, settings)


def _detectors(weights: Path | None) -> dict[str, BerryDetector]:
    if weights is None:
        return {name: detector(name) for name in DETECTORS}
    return {
        "colour": detector("colour"),
        "net": LearnedDetector(weights),
        "net+colour": ConfirmedDetector(weights),
    }


def run(conditions: dict[str, Path], weights: Path | None = None) -> dict[str, Any]:
    """{condition: {detector: figures}} with ``ms_per_image``."""
    cv2.setNumThreads(1)
    out: dict[str, Any] = {}
    for name, folder in conditions.items():
        out[name] = {}
        for det_name, det in _detectors(weights).items():
            timed = _Timed(det)
            figures = evaluate(timed, folder / "annotations.json", folder)
            figures.pop("per_image")
            figures["ms_per_image"] = round(1000.0 * float(np.median(timed.seconds)), 1)
            out[name][det_name] = figures
    return out


def _cell(value: object) -> str:
    return "–" if value is None else f"{value:.3f}" if isinstance(value, float) else str(value)


def table(results: dict[str, Any]) -> str:
    """A markdown table: one row per condition and detector."""
    head = "| condition | detector | " + " | ".join(_SHOWN) + " | ripe counted | ms/image |"
    lines = [head, "|" + " --- |" * (len(_SHOWN) + 4)]
    for condition, by_detector in results.items():
        for det_name, f in by_detector.items():
            cells = " | ".join(_cell(f[k]) for k in _SHOWN)
            ripe = f["fruit_counted"]["ripe"]
            lines.append(f"| {condition} | {det_name} | {cells} | {ripe} | {f['ms_per_image']} |")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> None:
    """python -m softarm.experiments.detector_eval NAME=FOLDER ... [--weights W] [--out F]."""
    p = argparse.ArgumentParser(prog="python -m softarm.experiments.detector_eval")
    p.add_argument("conditions", nargs="+", help="NAME=FOLDER (softarm dataset output)")
    p.add_argument("--weights", type=Path, help="the network to score (default: shipped)")
    p.add_argument("--note", default="", help="a line stored with the figures")
    p.add_argument("--out", type=Path, help="JSON file for the figures")
    a = p.parse_args(argv)
    conditions = {}
    for item in a.conditions:
        name, _, folder = item.partition("=")
        if not folder:
            p.error(f"{item!r}: expected NAME=FOLDER")
        conditions[name] = Path(folder)
    results = run(conditions, a.weights)
    print(table(results))
    if a.out is not None:
        doc = {
            "note": a.note,
            "folders": {k: str(v) for k, v in conditions.items()},
            "results": results,
        }
        a.out.write_text(json.dumps(doc, indent=1) + "\n")


if __name__ == "__main__":
    main()
