"""Scoring one frame pair of the daylight row against the renderer's ground truth, and
pooling the scores of a cell's seeds (the perception map, :mod:`.perception_map`).

* Detection: the tallies of ``softarm detector evaluate``
  (:class:`~softarm.perception.detector.scoring.Tally`) on C1's left eye: a detection is
  a fruit's when their masks overlap with IoU >= 0.3; recall and stage count the fruit
  at least half visible; ``ripe_precision`` is the share of ripe calls on ripe fruit.
* Stereo localisation of ripe berries: the ripe targets (ripe, at least half visible in
  the left eye) and the detections called ripe that the stereo placed; each pair, nearest
  first and each used once, closer than PAIR_GATE; a target is located when its pair is
  within LOCATED_WITHIN (the harvest's approach starts from there).
* Canes: :func:`~softarm.perception.cane_metrics.cane_map_error` of the fitted canes
  against every cane drawn (the bush's and the row's) in the arm's workspace.
* Wrong ripe calls, by what they are: the stage of the fruit they match, else what lies
  under their centre (``clutter``: a look-alike).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.perception.detector.scoring import MIN_VISIBLE, Tally

__all__ = ["LOCATED_WITHIN", "PAIR_GATE", "cell_summary", "stereo_counts"]

#: A stereo position farther than this (m) from every free ripe target pairs with none.
PAIR_GATE = 0.02
#: A ripe target is located when its stereo position is this close (m).
LOCATED_WITHIN = 0.010


def stereo_counts(
    targets: Mapping[int, FloatArray], located: Sequence[FloatArray]
) -> dict[str, Any]:
    """Pairs of ripe ``targets`` (fruit id -> true centre, base frame, m) and ``located``
    ripe detections' positions (base frame, m), nearest first: the number of targets,
    of those located within LOCATED_WITHIN, and every pair's error (mm)."""
    pairs = sorted(
        (float(np.linalg.norm(p - t)), i, fid)
        for i, p in enumerate(located)
        for fid, t in targets.items()
    )
    used_d: set[int] = set()
    used_t: set[int] = set()
    errors: list[float] = []
    for distance, i, fid in pairs:
        if distance > PAIR_GATE:
            break
        if i in used_d or fid in used_t:
            continue
        used_d.add(i)
        used_t.add(fid)
        errors.append(round(1000.0 * distance, 2))
    return {
        "targets": len(targets),
        "located": sum(e <= 1000.0 * LOCATED_WITHIN for e in errors),
        "errors_mm": errors,
    }


def _tally(counts: Iterable[Mapping[str, Any]]) -> Tally:
    """The tallies of several frames (``dataclasses.asdict`` of each) added up."""
    total = Tally()
    for c in counts:
        t = Tally(**{k: v for k, v in c.items()})
        total.images += t.images
        total.detections += t.detections
        total.false += t.false
        total.ripe_calls += t.ripe_calls
        total.ripe_calls_right += t.ripe_calls_right
        for stage in total.counted:
            total.counted[stage] += t.counted[stage]
            total.found[stage] += t.found[stage]
            for k in total.confusion[stage]:
                total.confusion[stage][k] += t.confusion[stage][k]
        total.unstaged = [a + b for a, b in zip(total.unstaged, t.unstaged, strict=True)]
        total.errors_mm += t.errors_mm
    return total


def tally_counts(tally: Tally) -> dict[str, Any]:
    """A frame's tally as plain data (what a trial returns)."""
    return dataclasses.asdict(tally)


def _ratio(a: float, b: float) -> float | None:
    return None if b == 0 else round(a / b, 3)


def _detector_summary(frames: list[Mapping[str, Any]]) -> dict[str, Any]:
    figures = _tally(f["tally"] for f in frames).figures()
    out: dict[str, Any] = {
        k: figures[k] for k in ("ripe_precision", "recall_ripe", "precision", "stage_right")
    }
    out = {k: None if v is None else round(v, 3) for k, v in out.items()}
    wrong: dict[str, int] = {}
    for f in frames:
        for what, n in f.get("wrong_ripe_on", {}).items():
            wrong[what] = wrong.get(what, 0) + n
    out["wrong_ripe_on"] = dict(sorted(wrong.items()))
    stereo = [f["stereo"] for f in frames if f.get("stereo") is not None]
    if stereo:
        targets = sum(s["targets"] for s in stereo)
        errors = [e for s in stereo for e in s["errors_mm"]]
        out["located"] = _ratio(sum(s["located"] for s in stereo), targets)
        out["stereo_median_mm"] = round(float(np.median(errors)), 1) if errors else None
    return out


def _cane_summary(canes: list[Mapping[str, Any]]) -> dict[str, Any]:
    length = np.array([c["length_m"] for c in canes])
    medians = [c["median_mm"] for c in canes if c["median_mm"] is not None]
    # A frame with no fitted cane in the workspace has no distances and no precision.
    fitted = [c["precision"] for c in canes if c["median_all_mm"] is not None]
    coverage = np.sum(length * [c["coverage"] for c in canes]) / np.sum(length)
    return {
        "coverage": round(float(coverage), 3) if np.sum(length) > 0 else None,
        "precision": round(float(np.mean(fitted)), 3) if fitted else None,
        "median_mm": round(float(np.median(medians)), 1) if medians else None,
        "frames_without_fit": len(canes) - len(fitted),
    }


def cell_summary(rows: Sequence[Mapping[str, Any]], detectors: Sequence[str]) -> dict[str, Any]:
    """One cell's figures pooled over its seeds' ``rows`` (trial results; failed ones
    counted, not scored): per detector the pooled tallies' ripe precision, ripe recall,
    precision, stage right and the stereo's located share and median error; the cane
    map's length-weighted coverage, mean precision over the frames with a fit in the
    workspace, median of the frames' medians and the frames without one."""
    good = [r for r in rows if r.get("error") is None]
    out: dict[str, Any] = {
        "frames": len(good),
        "failed": len(rows) - len(good),
        "fruit_in_view": round(float(np.mean([r["fruit_in_view"] for r in good])), 1)
        if good
        else None,
        "ripe_targets": sum(r["ripe_targets"] for r in good),
    }
    out["detectors"] = {d: _detector_summary([r["detectors"][d] for r in good]) for d in detectors}
    canes = [r["canes"] for r in good if r.get("canes") is not None]
    if canes:
        out["canes"] = _cane_summary(canes)
    return out


def is_counted(visible: float) -> bool:
    """Whether a fruit this visible counts for recall (the evaluator's rule)."""
    return visible >= MIN_VISIBLE
