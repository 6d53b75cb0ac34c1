"""Which labelled fruit a detector misses, and what they have in common: each ripe fruit
at least half visible (the fruit the recall goal counts) with whether a detection
matched it and what might explain a miss: its apparent radius (px, the whole fruit's,
from its visible area and share), its visible share, its distance, the light on it (the
mean grey of its pixels), whether it touches another fruit, and the best mask IoU any
detection has with it (a miss with some overlap is a merge, whose detection matches at
most one of the fruit it covers, or a fragment; with none, the fruit was not proposed
at all). :func:`miss_table` bins them as docs/perception.md shows them."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import InputError
from softarm.files.images import read_image
from softarm.perception.berries import BerryDetection
from softarm.perception.detector.choice import BerryDetector
from softarm.perception.detector.evaluate import _camera
from softarm.perception.detector.labels import LabelledObject, read_coco
from softarm.perception.detector.scoring import MIN_VISIBLE, match

__all__ = ["BINS", "FruitCase", "fruit_cases", "miss_table"]

#: Pixels around a fruit's mask in which another fruit's pixels count as touching it.
TOUCH_PX = 2


@dataclass(frozen=True)
class FruitCase:
    """One ripe fruit at least half visible, and whether the detector found it."""

    found: bool
    radius_px: float
    visible: float
    distance_m: float | None
    grey: float
    touches: bool
    best_iou: float
    view: str


def _best_iou(dets: list[BerryDetection], mask: npt.NDArray[np.bool_]) -> float:
    area, best = int(np.count_nonzero(mask)), 0.0
    for d in dets:
        x, y = d.mask_offset
        h, w = d.mask.shape
        window = mask[y : y + h, x : x + w]
        inter = np.count_nonzero(d.mask[: window.shape[0], : window.shape[1]] & window)
        if inter:
            best = max(best, inter / (np.count_nonzero(d.mask) + area - inter))
    return float(best)


def _cases(
    image: npt.NDArray[np.uint8], fruit: list[LabelledObject], dets: list[BerryDetection], view: str
) -> list[FruitCase]:
    found = set(match(dets, fruit).values())
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    owner = np.zeros(grey.shape, np.int32)
    for j, f in enumerate(fruit):
        owner[f.mask] = j + 1
    kernel = np.ones((2 * TOUCH_PX + 1, 2 * TOUCH_PX + 1), np.uint8)
    out = []
    for j, f in enumerate(fruit):
        if f.stage != "ripe" or f.visible is None or f.visible < MIN_VISIBLE:
            continue
        near = owner[cv2.dilate(f.mask.astype(np.uint8), kernel) > 0]
        area = int(np.count_nonzero(f.mask))
        out.append(
            FruitCase(
                found=j in found,
                radius_px=float(np.sqrt(area / f.visible / np.pi)),
                visible=f.visible,
                distance_m=None if f.position is None else float(np.linalg.norm(f.position)),
                grey=float(grey[f.mask].mean()),
                touches=bool(np.any((near > 0) & (near != j + 1))),
                best_iou=_best_iou(dets, f.mask),
                view=str(view),
            )
        )
    return out


def fruit_cases(detector: BerryDetector, folder: str | Path) -> list[FruitCase]:
    """The ripe fruit at least half visible of a labelled folder (``softarm dataset``
    output: annotations.json with visible shares) and what ``detector`` made of them.

    Raises:
        InputError: the folder's labels cannot be read or name no image in it, or an
            image named cannot be read.
    """
    folder = Path(folder)
    items = read_coco(folder / "annotations.json", folder)
    if not items:
        raise InputError(f"folder {folder}: its labels name no image in it")
    out: list[FruitCase] = []
    for item in items:
        image = cast(npt.NDArray[np.uint8], read_image(item.path, "image", cv2.IMREAD_COLOR))
        dets = list(detector.detect_berries(image, _camera(item, None), None))
        fruit = [o for o in item.objects() if o.is_fruit]
        out.extend(_cases(image, fruit, dets, str(item.record.get("view", "?"))))
    return out


#: What the fruit are binned by: (heading, the value of a case, bin edges).
BINS: tuple[tuple[str, Callable[[FruitCase], float], tuple[float, ...]], ...] = (
    ("apparent radius (px)", lambda c: c.radius_px, (0, 5, 7, 9, 12, 20, 1e9)),
    ("visible share", lambda c: c.visible, (0.5, 0.7, 0.9, 1.01)),
    ("distance (m)", lambda c: np.nan if c.distance_m is None else c.distance_m,
     (0, 0.3, 0.6, 0.9, 1.2, 1e9)),
    ("mean grey of its pixels", lambda c: c.grey, (0, 12, 18, 25, 256)),
    ("touches other fruit (0 no, 1 yes)", lambda c: float(c.touches), (0, 1, 2)),
    ("camera (0 C1, 1 C2)", lambda c: float(c.view.startswith("c2")), (0, 1, 2)),
)  # fmt: skip


def miss_table(cases: Sequence[FruitCase]) -> str:
    """Markdown: for each of BINS, per bin the fruit, those missed and the recall."""
    lines = ["| by | bin | ripe ≥ ½ visible | missed | recall |", "| --- | --- | --- | --- | --- |"]
    for heading, value, edges in BINS:
        for lo, hi in itertools.pairwise(edges):
            inside = [c for c in cases if lo <= value(c) < hi]
            if inside:
                n_missed = sum(not c.found for c in inside)
                recall = 1.0 - n_missed / len(inside)
                span = f"{lo:g}–{hi:g}" if hi < 1e9 else f"≥ {lo:g}"
                lines.append(f"| {heading} | {span} | {len(inside)} | {n_missed} | {recall:.2f} |")
    missed = [c for c in cases if not c.found]
    merged = sum(c.best_iou > 0 for c in missed)
    lines.append(
        f"\n{len(missed)} of {len(cases)} missed: {merged} overlapped by a detection not matched "
        f"to it (a merge or a fragment; {sum(c.best_iou > 0 and c.touches for c in missed)}"
        f" of them touching another fruit), {len(missed) - merged} with no detection on them."
    )
    return "\n".join(lines)
