"""Where C1's stereo loses the row's canes: the loss chain of the cane fit, stage by
stage, in metres of true cane within the arm's workspace (issue 41).

Each true cane centre line is sampled every millimetre (as
:func:`~softarm.perception.cane_metrics.cane_map_error` samples it) and each sample
within the workspace (0.6 m of the base) is followed down the chain; a stage keeps a
sample only where every stage before it did, so the chain only falls:

``workspace``: every sample; ``in_view``: it projects inside both of C1's frames, in
front of them and within the stereo's depth range (``CaneSettings.depth_range``);
``left``: the renderer's instance mask of the left eye shows this very cane (its id)
within a pixel of the sample's projection (the cane is not hidden there by a leaf, a
berry or another cane); ``both``: the right eye's does too (the ceiling: what any
stereo could place); ``mask``: the chosen cane mask (``colour`` or ``net``, on the
rectified left image) holds a pixel within a pixel of it; ``matched``: one of those
mask pixels has a disparity; ``placed``: a point the stereo placed from the mask
(within the map's reach, before the budget) lies within 10 mm of the sample;
``budget``: a point of the fit's input (the budget's even subsample) does; ``fitted``:
a fitted curve passes within 10 mm (``coverage_all``, the same without the chain,
is :func:`cane_map_error`'s coverage).

Run one look's seeds in parts and pool them after::

    MUJOCO_GL=egl python -m softarm.experiments.cane_losses run sun 311000 311005 --out losses/
    python -m softarm.experiments.cane_losses table losses/ --out docs/data/cane_losses.json

It lives above :mod:`softarm.perception` (which may not import the simulation).
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from softarm.checks import FloatArray
from softarm.perception.cane_curves import curve_points
from softarm.perception.cane_metrics import DEFAULT_REACH, SPACING
from softarm.perception.canes import (
    CaneFit,
    CaneSettings,
    even_subsample,
    fit_cane_points,
    mask_points,
)
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["STAGES", "LossViews", "loss_chain", "main", "summarise"]

#: The stages, in the order of the chain (see the module docstring).
STAGES = (
    "workspace", "in_view", "left", "both", "mask", "matched", "placed", "budget", "fitted"
)  # fmt: skip
#: The looks and the rendered bush, as in :mod:`softarm.experiments.cane_sources`.
CONDITIONS = ("sun", "overcast", "dusk", "backlight", "bush")
#: A point or a curve this near a sample (m) covers it, as ``cane_map_error`` counts it.
WITHIN = 0.010
#: Pixels each side of a sample's projection searched in the masks (a 3 x 3 window).
NEAR_PX = 1


@dataclass(frozen=True)
class LossViews:
    """What one C1 frame gives the chain: ``left_ids``, ``right_ids`` (H, W) the cane
    index each pixel of the (distorted) left and right frames shows, -1 where no cane;
    ``mask`` (H, W) the cane mask of the rectified left image and ``disparity`` its
    disparity (NaN unmatched); ``placed`` (n, 4) the stereo's points within the reach
    before the budget, ``points`` the fit's input and ``fits`` the fitted canes."""

    stereo: StereoCamera
    left_ids: npt.NDArray[np.int32]
    right_ids: npt.NDArray[np.int32]
    mask: npt.NDArray[np.bool_]
    disparity: npt.NDArray[np.float32]
    placed: FloatArray
    points: FloatArray
    fits: Sequence[CaneFit]


def loss_chain(
    canes: Sequence[Any],
    views: LossViews,
    depth_range: tuple[float, float] = (0.6, 1.5),
    workspace: float = DEFAULT_REACH,
) -> dict[str, float]:
    """Metres of true cane (``canes``: anything with ``coeffs``, their index the id in
    the instance masks) within ``workspace`` of the base that reach each stage of
    :data:`STAGES`, and ``coverage_all``: the share within 10 mm of a fit."""
    samples, ids = _samples(canes, workspace)
    flags = {"workspace": np.ones(len(samples), bool)}
    left_px, right_px, in_view = _projections(samples, views.stereo, depth_range)
    flags["in_view"] = in_view
    flags["left"] = _shows(views.left_ids, left_px, ids, in_view)
    flags["both"] = flags["left"] & _shows(views.right_ids, right_px, ids, in_view)
    rect_px = np.zeros_like(left_px)
    if in_view.any():
        rect_px[in_view] = views.stereo.rectification.to_rectified_pixels(left_px[in_view])
    matched = views.mask & np.isfinite(views.disparity)
    flags["mask"] = flags["both"] & _any_near(views.mask, rect_px, in_view)
    flags["matched"] = flags["mask"] & _any_near(matched, rect_px, in_view)
    flags["placed"] = flags["matched"] & _near_points(samples, views.placed)
    flags["budget"] = flags["placed"] & _near_points(samples, views.points)
    fitted = _near_points(samples, _fit_samples(views.fits))
    flags["fitted"] = flags["budget"] & fitted
    out = {stage: float(np.count_nonzero(flags[stage])) * SPACING for stage in STAGES}
    out["coverage_all"] = float(np.mean(fitted)) if len(samples) else 1.0
    return out


def _samples(canes: Sequence[Any], workspace: float) -> tuple[FloatArray, npt.NDArray[np.intp]]:
    """Points every millimetre along each cane within ``workspace`` of the base, and
    each point's cane index."""
    parts, ids = [np.zeros((0, 3))], [np.zeros(0, np.intp)]
    for index, cane in enumerate(canes):
        coeffs = np.asarray(cane.coeffs, np.float64)
        coarse = curve_points(coeffs, 200)
        length = float(np.sum(np.linalg.norm(np.diff(coarse, axis=0), axis=1)))
        points = curve_points(coeffs, max(2, int(np.ceil(length / SPACING)) + 1))
        points = points[np.linalg.norm(points, axis=1) <= workspace]
        parts.append(points)
        ids.append(np.full(len(points), index, np.intp))
    return np.vstack(parts), np.concatenate(ids)


def _projections(
    samples: FloatArray, stereo: StereoCamera, depth_range: tuple[float, float]
) -> tuple[FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    """Each sample's (distorted) pixel in the left and right frames and whether it lies
    within both frames and the depth range (pixels of the others are 0)."""
    n = len(samples)
    pixels, inside = [np.zeros((n, 2)), np.zeros((n, 2))], np.ones(n, bool)
    T_left = np.asarray(stereo.T_base_left, np.float64)
    for eye, (camera, T_base) in enumerate(
        [(stereo.left, T_left), (stereo.right, T_left @ np.asarray(stereo.T_left_right))]
    ):
        T = np.linalg.inv(T_base)
        local = samples @ T[:3, :3].T + T[:3, 3]
        front = local[:, 2] >= (depth_range[0] if eye == 0 else 1e-3)
        if eye == 0:
            front &= local[:, 2] <= depth_range[1]
        inside &= front
        if not front.any():
            continue
        pixels[eye][front] = camera.project(local[front])
        w, h = camera.image_size or (0, 0)
        px = pixels[eye]
        inside &= (px[:, 0] >= 0) & (px[:, 0] <= w - 1) & (px[:, 1] >= 0) & (px[:, 1] <= h - 1)
    return pixels[0], pixels[1], inside


def _windows(
    shape: tuple[int, ...], pixels: FloatArray
) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]]:
    """Rows and columns (n, k) of the (2 NEAR_PX + 1)² pixels around each of ``pixels``,
    clamped into an image of ``shape``."""
    offsets = np.arange(-NEAR_PX, NEAR_PX + 1)
    dy, dx = (g.ravel() for g in np.meshgrid(offsets, offsets, indexing="ij"))
    centre = np.rint(pixels).astype(np.intp)
    rows = np.clip(centre[:, 1:2] + dy, 0, shape[0] - 1)
    cols = np.clip(centre[:, 0:1] + dx, 0, shape[1] - 1)
    return rows, cols


def _shows(
    ids: npt.NDArray[np.int32], pixels: FloatArray, cane: npt.NDArray[np.intp],
    inside: npt.NDArray[np.bool_],
) -> npt.NDArray[np.bool_]:  # fmt: skip
    """Whether the instance image ``ids`` shows each sample's own cane near its pixel."""
    rows, cols = _windows(ids.shape, pixels)
    result: npt.NDArray[np.bool_] = inside & np.any(ids[rows, cols] == cane[:, None], axis=1)
    return result


def _any_near(
    image: npt.NDArray[np.bool_], pixels: FloatArray, inside: npt.NDArray[np.bool_]
) -> npt.NDArray[np.bool_]:
    """Whether ``image`` is set near each of ``pixels`` (rectified)."""
    rows, cols = _windows(image.shape, pixels)
    result: npt.NDArray[np.bool_] = inside & np.any(image[rows, cols], axis=1)
    return result


def _near_points(samples: FloatArray, points: FloatArray) -> npt.NDArray[np.bool_]:
    """Whether a row of ``points`` (n, 3+) lies within WITHIN of each sample."""
    if len(points) == 0 or len(samples) == 0:
        return np.zeros(len(samples), bool)
    distance = cKDTree(np.asarray(points)[:, :3]).query(samples)[0]
    result: npt.NDArray[np.bool_] = distance <= WITHIN
    return result


def _fit_samples(fits: Sequence[CaneFit]) -> FloatArray:
    """The fitted curves drawn densely (about every millimetre)."""
    if not fits:
        return np.zeros((0, 3))
    return np.vstack([curve_points(np.asarray(f.coeffs, np.float64), 2000) for f in fits])


def scene_rows(
    condition: str, seed: int, sources: Sequence[str], settings: CaneSettings, label: str
) -> list[dict[str, Any]]:
    """One row per source: ``seed``'s bush in ``condition``, C1 where it truly is, the
    arm out of view, ``settings`` the fit's (``label`` names them in the rows)."""
    from softarm.perception.cane_pixels import cane_mask, matched_disparity
    from softarm.perception.cane_source import candidate_masks

    rect_left, rect_right, stereo, canes, ids = _render(condition, seed)
    look = settings.look
    masks = {"colour": cane_mask(rect_left, look)} if set(sources) <= {"colour"} else {}
    masks = masks or candidate_masks(rect_left, look)
    rows = []
    for source in sources:
        mask = masks[source]
        disparity = matched_disparity(
            rect_left, rect_right, stereo.rectification, mask, settings.depth_range,
            settings.match_far, settings.smoothness, settings.ties_in_range,
        )  # fmt: skip
        whole = replace(settings, max_points=10**9)
        placed = mask_points(rect_left, rect_right, stereo, mask, whole)
        points = even_subsample(placed, settings.max_points)
        fits = fit_cane_points(points, settings)
        views = LossViews(stereo, ids[0], ids[1], mask, disparity, placed, points, fits)
        chain = loss_chain(canes, views, settings.depth_range)
        rows.append({
            "condition": condition, "seed": seed, "source": source, "settings": label,
            **chain, "mask_px": int(mask.sum()), "points": len(points), "fits": len(fits),
        })  # fmt: skip
    return rows


def _render(condition: str, seed: int) -> tuple[Any, Any, StereoCamera, list[Any], Any]:
    """C1's rectified pair of ``seed``'s bush (8 berries, as ``cane_sources`` draws it)
    in ``condition``, its stereo, every cane drawn and the cane index each pixel of the
    left and right frames shows."""
    from softarm.experiments.cane_sources import rendered_bush
    from softarm.sim.render.labels import KINDS

    world = rendered_bush(condition, seed, 8)
    try:
        frames = world.c1(truth=True)
        canes = world.canes()
        labels = world.labels
    finally:
        world.close()
    ids = []
    for frame in frames:
        assert frame.geoms is not None  # asked for
        g = np.maximum(frame.geoms, 0)
        cane = (frame.geoms >= 0) & (labels.kind[g] == KINDS.index("cane"))
        ids.append(np.where(cane, labels.instance[g], -1).astype(np.int32))
    stereo = world.stereo
    rect_left, rect_right = stereo.rectification.rectify(frames[0].colour, frames[1].colour)
    return rect_left, rect_right, stereo, canes, ids


def summarise(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per condition, source and settings: each stage's metres pooled over the scenes
    and as a share of the workspace's length, and the pooled ``coverage_all``."""
    out = []
    keys = sorted({(r["condition"], r["source"], r["settings"]) for r in rows})
    for condition, source, label in keys:
        key = (condition, source, label)
        mine = [r for r in rows if (r["condition"], r["source"], r["settings"]) == key]
        total = {stage: sum(r[stage] for r in mine) for stage in STAGES}
        whole = max(total["workspace"], 1e-9)
        coverage = sum(r["coverage_all"] * r["workspace"] for r in mine) / whole
        out.append({
            "condition": condition, "source": source, "settings": label, "scenes": len(mine),
            "seeds": [min(r["seed"] for r in mine), max(r["seed"] for r in mine)],
            "metres": {s: round(v, 3) for s, v in total.items()},
            "share": {s: round(v / whole, 3) for s, v in total.items()},
            "coverage_all": round(coverage, 3),
        })  # fmt: skip
    return out


def table_lines(summary: Sequence[dict[str, Any]]) -> list[str]:
    """The summary as a markdown table: each stage's share of the workspace's cane."""
    lines = [
        "| look | source | scenes | " + " | ".join(STAGES[1:]) + " | coverage (all) |",
        "| --- | --- | --- |" + " --- |" * len(STAGES),
    ]
    for row in summary:
        cells = " | ".join(str(row["share"][s]) for s in STAGES[1:])
        name = (
            row["source"] if row["settings"] == "default" else f"{row['source']}, {row['settings']}"
        )
        lines.append(
            f"| {row['condition']} | `{name}` | {row['scenes']} | {cells} | {row['coverage_all']} |"
        )
    return lines


def _run(args: argparse.Namespace) -> None:
    from softarm.experiments.cane_sources import BUDGETS

    settings = CaneSettings() if args.budget == "default" else BUDGETS[args.budget]
    folder = Path(args.out)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{args.condition}_{args.budget}_{args.first}_{args.last}.jsonl"
    with path.open("w") as f:
        for seed in range(args.first, args.last + 1):
            for row in scene_rows(args.condition, seed, args.sources, settings, args.budget):
                f.write(json.dumps(row) + "\n")
            f.flush()
            print(args.condition, seed, flush=True)


def _table(args: argparse.Namespace) -> None:
    rows = [
        json.loads(line)
        for folder in args.folders
        for path in sorted(Path(folder).glob("*.jsonl"))
        for line in path.read_text().splitlines()
    ]
    summary = summarise(rows)
    for line in table_lines(summary):
        print(line)
    if args.out:
        Path(args.out).write_text(json.dumps(summary, indent=1) + "\n")


def main(argv: list[str] | None = None) -> None:
    """``run CONDITION FIRST LAST --out DIR`` or ``table DIR... [--out FILE]``."""
    from softarm.experiments.cane_sources import BUDGETS

    parser = argparse.ArgumentParser(prog="python -m softarm.experiments.cane_losses")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="the loss chain on seeds FIRST..LAST")
    run.add_argument("condition", choices=CONDITIONS)
    run.add_argument("first", type=int)
    run.add_argument("last", type=int)
    run.add_argument("--out", required=True, help="folder for the rows (JSON lines)")
    run.add_argument(
        "--sources", nargs="+", choices=("colour", "net", "net+colour"),
        default=["colour", "net"], help="the cane masks followed",
    )  # fmt: skip
    run.add_argument(
        "--budget", choices=("default", *BUDGETS), default="default",
        help="the fit's settings: today's default or one of cane_sources' budgets",
    )  # fmt: skip
    table = sub.add_parser("table", help="the chain pooled over the rows in FOLDERS")
    table.add_argument("folders", nargs="+")
    table.add_argument("--out", help="the summary as JSON")
    args = parser.parse_args(argv)
    _run(args) if args.command == "run" else _table(args)


if __name__ == "__main__":
    main()
