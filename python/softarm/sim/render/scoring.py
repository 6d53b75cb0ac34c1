"""Berry perception scored against the rendered ground truth: detection precision and
recall for the ripe berries at least half visible in C1, ripe-against-unripe accuracy,
and the stereo localisation error, per bush (docs/perception.md's tables come from
:mod:`softarm.experiments.perception`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
import numpy.typing as npt

from softarm.perception.berries import BerryDetection
from softarm.sim.render.world import RenderedBush

__all__ = ["BerryScore", "score_berries"]

#: A berry counts as "in view" for recall when at least this share of it is visible.
HALF_VISIBLE = 0.5


@dataclass
class BerryScore:
    """Counts and errors of one bush (or summed over several)."""

    ripe_detections: int = 0
    ripe_true_positives: int = 0
    ripe_in_view: int = 0
    ripe_found: int = 0
    classified: int = 0
    classified_right: int = 0
    errors_mm: list[float] = field(default_factory=list)
    distances_m: list[float] = field(default_factory=list)
    seconds: list[float] = field(default_factory=list)

    def add(self, other: BerryScore) -> None:
        """Sum ``other`` into this score."""
        for name, value in vars(other).items():
            setattr(self, name, getattr(self, name) + value)

    def summary(self) -> dict[str, float | tuple[float, float]]:
        """Precision, recall, ripeness accuracy, localisation median/p95 (mm), time."""
        e = np.asarray(self.errors_mm)
        return {
            "precision": self.ripe_true_positives / max(self.ripe_detections, 1),
            "recall": self.ripe_found / max(self.ripe_in_view, 1),
            "ripeness_accuracy": self.classified_right / max(self.classified, 1),
            "ripe_in_view": self.ripe_in_view,
            "localised": int(e.size),
            "median_mm": float(np.median(e)) if e.size else float("nan"),
            "p95_mm": float(np.percentile(e, 95)) if e.size else float("nan"),
            "distance_m": _span(self.distances_m),
            "median_s": float(np.median(self.seconds)) if self.seconds else float("nan"),
        }


def score_berries(world: RenderedBush, detections: list[BerryDetection]) -> BerryScore:
    """Score ``detections`` (from :func:`locate_berries` on the world's C1 pair, in the
    rectified left image) against the world's truth as the arm is drawn now."""
    left, _ = world.c1(truth=True)
    shares = world.berry_shares(left)
    rect = world.stereo.rectification
    assert left.geoms is not None
    score = BerryScore()
    claimed: set[int] = set()
    for berry in world.bush.berries:
        visible = world.labels.mask(left.geoms, "berry", berry.tag_id)
        share = shares[berry.tag_id]
        region = _rectified(visible, rect.maps[0])
        hits = [i for i, d in enumerate(detections) if _inside(d, region) and i not in claimed]
        ripe = berry.ripeness >= 0.5
        for i in hits[:1]:
            claimed.add(i)
            d = detections[i]
            score.classified += 1
            score.classified_right += (d.ripeness == "ripe") == ripe
            if ripe and d.ripeness == "ripe":
                score.ripe_true_positives += 1
        if ripe and share >= HALF_VISIBLE:
            score.ripe_in_view += 1
            found = [detections[i] for i in hits[:1] if detections[i].ripeness == "ripe"]
            score.ripe_found += bool(found)
            if found and found[0].position is not None:
                err = np.linalg.norm(found[0].position - berry.position)
                score.errors_mm.append(1000.0 * float(err))
                eye = world.stereo.T_base_left[:3, 3]
                score.distances_m.append(float(np.linalg.norm(berry.position - eye)))
    score.ripe_detections = sum(d.ripeness == "ripe" for d in detections)
    return score


def _rectified(
    mask: npt.NDArray[np.bool_], maps: tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]
) -> npt.NDArray[np.bool_]:
    """A left-eye mask on the rectified grid."""
    m = cv2.remap(mask.astype(np.uint8), maps[0], maps[1], cv2.INTER_NEAREST)
    return cv2.dilate(m, np.ones((5, 5), np.uint8)) > 0


def _inside(det: BerryDetection, region: npt.NDArray[np.bool_]) -> bool:
    x, y = round(det.center[0]), round(det.center[1])
    h, w = region.shape
    return 0 <= x < w and 0 <= y < h and bool(region[y, x])


def _span(values: list[float]) -> tuple[float, float]:
    return (min(values), max(values)) if values else (float("nan"), float("nan"))
