"""Scoring berry detections against labelled fruit: matching and the tallies of
precision, recall, stage and localisation that ``softarm detector evaluate`` reports.

A detection matches a labelled fruit when their masks overlap with an IoU of at least
MATCH_IOU, greedily, the largest overlaps first, each at most once. A detection that
matches no fruit is a false one. Recall and the stage figures count the fruit at least
half visible (or of unknown visible share: photos); a detection matching a fruit less
visible than that is neither right nor wrong. "Stage right" is ripe against not ripe
(turning or unripe), on the matched fruit of known stage.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softarm.perception.berries import BerryDetection
from softarm.perception.detector.labels import FRUIT_STAGES, LabelledObject

__all__ = ["MATCH_IOU", "MIN_VISIBLE", "Tally", "match", "stage_of_detection"]

#: Mask IoU at which a detection is a labelled fruit's.
MATCH_IOU = 0.3
#: Fruit less visible than this is not counted for recall or stage.
MIN_VISIBLE = 0.5
_PREDICTED = ("ripe", "turning", "unripe")


def stage_of_detection(det: BerryDetection) -> str:
    """A detection's stage: its own where it has one (the network's), else its ripeness."""
    stage = getattr(det, "stage", None)
    return stage if isinstance(stage, str) else ("ripe" if det.ripeness == "ripe" else "unripe")


def match(dets: list[BerryDetection], fruit: list[LabelledObject]) -> dict[int, int]:
    """detection index -> fruit index of the matched pairs."""
    pairs = []
    for i, d in enumerate(dets):
        x, y = d.mask_offset
        h, w = d.mask.shape
        for j, f in enumerate(fruit):
            window = f.mask[y : y + h, x : x + w]
            inter = np.count_nonzero(d.mask[: window.shape[0], : window.shape[1]] & window)
            if inter:
                iou = inter / (np.count_nonzero(d.mask) + np.count_nonzero(f.mask) - inter)
                if iou >= MATCH_IOU:
                    pairs.append((iou, i, j))
    out: dict[int, int] = {}
    used: set[int] = set()
    for _, i, j in sorted(pairs, reverse=True):
        if i not in out and j not in used:
            out[i] = j
            used.add(j)
    return out


def _counted(f: LabelledObject) -> bool:
    return f.visible is None or f.visible >= MIN_VISIBLE


@dataclass
class Tally:
    """Running counts over images; :meth:`figures` gives the report."""

    images: int = 0
    detections: int = 0
    false: int = 0
    ripe_calls: int = 0
    ripe_calls_right: int = 0
    counted: dict[str, int] = field(default_factory=lambda: dict.fromkeys(FRUIT_STAGES, 0))
    found: dict[str, int] = field(default_factory=lambda: dict.fromkeys(FRUIT_STAGES, 0))
    unstaged: list[int] = field(default_factory=lambda: [0, 0])  # counted, found
    confusion: dict[str, dict[str, int]] = field(
        default_factory=lambda: {s: dict.fromkeys((*_PREDICTED, "missed"), 0) for s in FRUIT_STAGES}
    )
    errors_mm: list[float] = field(default_factory=list)

    def add(
        self,
        dets: list[BerryDetection],
        fruit: list[LabelledObject],
        truth: list[np.ndarray[Any, Any] | None] | None = None,
    ) -> dict[int, int]:
        """Count one image; ``truth`` the fruit's positions (m) in the camera frame where
        known, for the localisation error. Returns the matches."""
        pairs = match(dets, fruit)
        self.images += 1
        self.detections += len(dets)
        self.false += len(dets) - len(pairs)
        for i, d in enumerate(dets):
            if d.ripeness == "ripe":
                j = pairs.get(i)
                staged = j is not None and fruit[j].stage in FRUIT_STAGES
                if j is None or staged:
                    self.ripe_calls += 1
                    self.ripe_calls_right += int(staged and fruit[j].stage == "ripe")  # type: ignore[index]
        found = {j: i for i, j in pairs.items()}
        for j, f in enumerate(fruit):
            if not _counted(f):
                continue
            k = found.get(j)
            if f.stage not in FRUIT_STAGES:
                self.unstaged[0] += 1
                self.unstaged[1] += int(k is not None)
                continue
            self.counted[f.stage] += 1
            if k is None:
                self.confusion[f.stage]["missed"] += 1
                continue
            self.found[f.stage] += 1
            self.confusion[f.stage][stage_of_detection(dets[k])] += 1
            p, t = dets[k].position, None if truth is None else truth[j]
            if p is not None and t is not None:
                self.errors_mm.append(float(np.linalg.norm(np.asarray(p) - t)) * 1000.0)
        return pairs

    def figures(self) -> dict[str, Any]:
        """Precision, recall (ripe, all), stage right, the confusion by stage and the
        localisation error (median and 95th percentile, mm) where depth was given."""
        matched = {
            s: sum(v for k, v in row.items() if k != "missed") for s, row in self.confusion.items()
        }
        right = self.confusion["ripe"]["ripe"] + sum(
            v
            for s in ("turning", "unripe")
            for k, v in self.confusion[s].items()
            if k in ("turning", "unripe")
        )
        n_matched = sum(matched.values())
        counted = sum(self.counted.values()) + self.unstaged[0]
        found = sum(self.found.values()) + self.unstaged[1]
        return {
            "images": self.images,
            "detections": self.detections,
            "false_detections": self.false,
            "precision": _ratio(self.detections - self.false, self.detections),
            "ripe_precision": _ratio(self.ripe_calls_right, self.ripe_calls),
            "recall_ripe": _ratio(self.found["ripe"], self.counted["ripe"]),
            "recall": _ratio(found, counted),
            "stage_right": _ratio(right, n_matched),
            "fruit_counted": dict(self.counted, no_stage=self.unstaged[0]),
            "confusion": self.confusion,
            "localisation_mm": None
            if not self.errors_mm
            else {
                "median": round(float(np.median(self.errors_mm)), 2),
                "p95": round(float(np.percentile(self.errors_mm, 95)), 2),
                "n": len(self.errors_mm),
            },
        }


def _ratio(a: int, b: int) -> float | None:
    return None if b == 0 else round(a / b, 4)
