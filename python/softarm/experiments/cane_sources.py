"""The cane pixels' sources side by side (:mod:`softarm.perception.cane_source`): on each
seed's bush, in each condition (the daylight row's looks, ``sun``, ``overcast``,
``dusk`` and ``backlight``, and the rendered bush, ``bush``), C1's stereo pair is
rendered once; every candidate's mask (``colour``, ``net`` and their intersection
``net+colour``; their union ``net|colour`` with ``--union``) goes through the same
stereo and curve fit (:func:`softarm.perception.canes.mask_points`,
:func:`~softarm.perception.canes.fit_cane_points`) twice, once per point budget
(``budget``: ``view``, the fit's points an even subsample of the whole view's, as
before the reach; ``reach``, the points beyond ``CaneSettings.reach`` dropped first),
and :func:`~softarm.perception.cane_metrics.cane_map_error` scores the fits against
every cane drawn (the bush's and, in the row, the row's) within the arm's reach. C1 is
where it truly is, the arm out of view; no depth from the renderer. ``fit_ms``: the
time of the stereo, the points and the fit of one C1 frame for one mask (the mask
itself not included), both budgets in the same process.

Rows are written one JSON line per scene, source and budget, so that seeds can be run in parts
(each part a process of a few minutes) and summed up after::

    MUJOCO_GL=egl python -m softarm.experiments.cane_sources run sun 310000 310024 --out rows/
    python -m softarm.experiments.cane_sources table rows/ --out docs/data/cane_sources.json

The summary per condition, source and budget: ``coverage`` pooled over the scenes by true cane
length; ``precision`` pooled by fitted length in the workspace (a scene without fits
adds nothing, where a mean of per-scene shares would count it as 1); ``median_mm`` the
median of the per-scene medians; ``fit_ms`` the median over the scenes.

It lives above :mod:`softarm.perception` (which may not import the simulation).
"""

from __future__ import annotations

import argparse
import itertools
import json
import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from softarm.perception.cane_curves import CurveSearch, curve_points
from softarm.perception.cane_evidence import CaneEvidence
from softarm.perception.cane_metrics import DEFAULT_REACH, cane_map_error
from softarm.perception.canes import (
    CaneFit,
    CaneSettings,
    even_subsample,
    fit_cane_points,
    mask_points,
)
from softarm.perception.self_filter import CANE_REACH, a_cane, rig_parts

__all__ = [
    "BUDGETS",
    "CONDITIONS",
    "SOURCES",
    "fitted_length",
    "rendered_bush",
    "scene_rows",
    "side_by_side",
    "summarise",
]

#: The row's looks and the rendered bush.
CONDITIONS = ("sun", "overcast", "dusk", "backlight", "bush")
#: The candidates, in the order of the table.
SOURCES = ("colour", "net", "net+colour", "net|colour")
#: Support counted in points, with the rule against specks before it counted among all
#: points (the budgets measured with it keep it, so that they run as they were measured).
_COUNTED = CurveSearch(min_support=70, support_length=0.0, speck_points=5, specks_among_all=False)
#: The point budgets and supports: ``view``, 4,000 points over the whole view, a cane 70
#: of them (as before the reach); ``before``, 4,000 points within the reach, a cane 70 of
#: them, a speck under 5 of its cane's points within 1 cm (the default before);
#: ``reach``, the default (a speck under 4 points of any kind within 1 cm); ``length``,
#: 8,000 points within the reach, a cane 8 cm of cane
#: covered and at least 20 points (``CurveSearch.support_length``; measured, not adopted);
#: ``evidence``, the ``length`` budget's fits kept only where they show a cane's evidence
#: (:class:`~softarm.perception.cane_evidence.CaneEvidence`); ``far``, the same budget
#: with C1's stereo matching out to 3 m (``CaneSettings.match_far``: the canes beyond the
#: range dropped at their own depth) and the evidence of 70 points and 1.75 mm alone,
#: a pixel whose match out to 3 m is tied left unmatched (as the far match was first
#: measured); ``ties``, the same with such a tie going to the match within the range
#: (``CaneSettings.ties_in_range``); ``ties_thin``, the same with a median radius of
#: 1.5 mm (the mask's half width, the largest distance to its edge less half a pixel,
#: reads a cane an even number of pixels wide half a pixel thin: the renderer's thinnest
#: canes, 2.5 mm, read 1.7 mm at 1.1 m).
_LENGTH = CurveSearch(min_support=20, support_length=0.08, speck_points=5, specks_among_all=False)
BUDGETS: dict[str, CaneSettings] = {
    "view": CaneSettings(
        reach=None, max_points=4000, search=_COUNTED, evidence=None, match_far=None
    ),
    # ``before``: the default before the specks were counted among all points
    "before": CaneSettings(max_points=4000, search=_COUNTED, evidence=None, match_far=None),
    "reach": CaneSettings(),
    "length": CaneSettings(max_points=8000, search=_LENGTH, evidence=None, match_far=None),
    "evidence": CaneSettings(
        max_points=8000, search=_LENGTH, evidence=CaneEvidence(), match_far=None
    ),
    "far": CaneSettings(
        max_points=8000,
        search=_LENGTH,
        evidence=CaneEvidence(min_density=0.0),
        match_far=3.0,
        ties_in_range=False,
    ),
    "ties": CaneSettings(
        max_points=8000,
        search=_LENGTH,
        evidence=CaneEvidence(min_density=0.0),
        match_far=3.0,
        ties_in_range=True,
    ),
    "ties_thin": CaneSettings(
        max_points=8000,
        search=_LENGTH,
        evidence=CaneEvidence(min_density=0.0, min_radius=0.0015),
        match_far=3.0,
        ties_in_range=True,
    ),
}


def fitted_length(fits: Sequence[CaneFit], reach: float = DEFAULT_REACH) -> float:
    """The fitted curves' length (m) within ``reach`` of the base origin, as
    :func:`cane_map_error` scores it."""
    total = 0.0
    for fit in fits:
        points = curve_points(np.asarray(fit.coeffs, np.float64), 400)
        inside = np.linalg.norm(points, axis=1) <= reach
        steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
        total += float(np.sum(steps[inside[1:] & inside[:-1]]))
    return total


def scene_rows(
    condition: str,
    seed: int,
    n_berries: int = 8,
    union: bool = False,
    only: Sequence[str] | None = None,
    budgets: Sequence[str] = tuple(BUDGETS),
) -> list[dict[str, Any]]:
    """One row per source and budget for ``seed``'s bush in ``condition`` (``union``:
    ``net|colour`` too; ``only``: just these sources; ``budgets``: just these). The
    ``kept_`` figures score only the fits the bush map keeps (none within
    ``SELF_MARGIN`` of the rig's own parts: :func:`~softarm.perception.self_filter.
    a_cane`), the others every fit."""
    from softarm.perception.cane_pixels import cane_mask
    from softarm.perception.cane_source import candidate_masks

    rect_left, rect_right, stereo, truth = _render(condition, seed, n_berries)
    look = CaneSettings().look
    if only is not None and set(only) <= {"colour"}:
        masks = {"colour": cane_mask(rect_left, look)}  # the network is not run for nothing
    else:
        masks = candidate_masks(rect_left, look)
    parts = _rig_parts()
    rows = []
    for source, mask in masks.items():
        if (source == "net|colour" and not union) or (only and source not in only):
            continue
        placed = _Placed(rect_left, rect_right, stereo, mask)
        for budget in budgets:
            settings = BUDGETS[budget]
            points, wall, cpu = placed.points(settings)
            start, start_cpu = time.perf_counter(), time.process_time()
            fits = fit_cane_points(points, settings)
            wall, cpu = wall + time.perf_counter() - start, cpu + time.process_time() - start_cpu
            kept = [f for f in fits if a_cane(f.points, parts, CANE_REACH)]
            scores = cane_map_error(kept, truth)
            rows.append({
                "condition": condition, "seed": seed, "source": source, "budget": budget,
                **cane_map_error(fits, truth), "fitted_m": fitted_length(fits),
                **{f"kept_{k}": v for k, v in scores.items()},
                "kept_fitted_m": fitted_length(kept), "fits": len(fits),
                "mask_px": int(mask.sum()), "points": len(points),
                "fit_ms": 1e3 * wall, "cpu_ms": 1e3 * cpu,
            })  # fmt: skip
    return rows


def rendered_bush(condition: str, seed: int, n_berries: int) -> Any:
    """``seed``'s bush of ``n_berries`` berries (40 % unripe) as the simulated rig's
    cameras see it (a :class:`~softarm.sim.render.RenderedBush`; the caller closes it),
    in ``condition``: a look of the row, or ``"bush"``."""
    import softarm
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.bush import Bush
    from softarm.sim.render import RenderedBush
    from softarm.sim.render.row_look import RowLook
    from softarm.sim.rig_cameras import BASE_TAG_ID

    cams = default_cameras()
    bush = Bush.generate(
        softarm.SoftArm.blackberry(), n_berries, seed,
        view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.4,
    )  # fmt: skip
    look = None if condition == "bush" else RowLook.named(condition, seed)
    return RenderedBush(
        bush, cams.T_base_c1, cams.model(1), cams.model(2), cams.T_ee_c2,
        cams.T_ee_cube, cams.T_base_tag, BASE_TAG_ID, cams.base_tag, look=look,
    )  # fmt: skip


def _render(condition: str, seed: int, n_berries: int) -> tuple[Any, Any, Any, Any]:
    """C1's rectified pair of ``seed``'s bush in ``condition``, its stereo and every
    cane drawn."""
    world = rendered_bush(condition, seed, n_berries)
    try:
        left, right = world.c1()
        truth = world.canes()
    finally:
        world.close()
    stereo = world.stereo
    rect_left, rect_right = stereo.rectification.rectify(left.colour, right.colour)
    return rect_left, rect_right, stereo, truth


def _rig_parts() -> Any:
    """What C1 sees of the simulated rig itself, as the simulated harvest gives it to
    the self-filter (the cube's box without its plates)."""
    import softarm
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.harvest_config import HarvestConfig

    cams = default_cameras()
    model = softarm.SoftArm.blackberry()
    return rig_parts(model, HarvestConfig(), cams.T_ee_cube, cams.T_base_tag)


class _Placed:
    """One mask's points, placed once per reach and stereo range (the stereo is the costly
    part) and each budget's even subsample of them taken after, as ``mask_points`` takes
    it; the time of the placing counted in every budget that uses it."""

    def __init__(self, rect_left: Any, rect_right: Any, stereo: Any, mask: Any) -> None:
        self.args = (rect_left, rect_right, stereo, mask)
        self.placed: dict[tuple[float, float | None, bool], tuple[Any, float, float]] = {}

    def points(self, settings: CaneSettings) -> tuple[Any, float, float]:
        """(points, wall seconds, CPU seconds) for ``settings``."""
        # without a reach the budget is spent on pixels before they are placed
        reach = settings.reach if settings.reach is not None else -float(settings.max_points)
        key = (reach, settings.match_far, settings.ties_in_range)
        if key not in self.placed:
            whole = settings if settings.reach is None else CaneSettings(max_points=10**9)
            start, start_cpu = time.perf_counter(), time.process_time()
            whole = replace(
                whole, reach=settings.reach, match_far=settings.match_far,
                ties_in_range=settings.ties_in_range,
            )  # fmt: skip
            points = mask_points(*self.args, whole)
            wall, cpu = time.perf_counter() - start, time.process_time() - start_cpu
            self.placed[key] = (points, wall, cpu)
        points, wall, cpu = self.placed[key]
        return even_subsample(points, settings.max_points), wall, cpu


def summarise(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per condition, source and budget (see the module docstring for the
    pooling); rows without a ``budget`` (written before the reach) count as ``view``."""
    out = []
    for condition, source, budget in itertools.product(CONDITIONS, SOURCES, BUDGETS):
        mine = [
            r for r in rows
            if (r["condition"], r["source"], r.get("budget", "view")) == (condition, source, budget)
        ]  # fmt: skip
        if mine:
            out.append(_summary(condition, source, budget, mine))
    return out


def _summary(
    condition: str, source: str, budget: str, mine: Sequence[dict[str, Any]]
) -> dict[str, Any]:
    """One row of :func:`summarise`: the figures of every fit and, where the rows have
    them, of the fits the map keeps (``kept_``)."""
    times = [r["fit_ms"] for r in mine if "fit_ms" in r]
    cpu = [r["cpu_ms"] for r in mine if "cpu_ms" in r]
    kept = _scores(mine, "kept_") if all("kept_coverage" in r for r in mine) else {}
    return {
        "condition": condition, "source": source, "budget": budget, "scenes": len(mine),
        **_scores(mine, ""), **{f"kept_{k}": v for k, v in kept.items()},
        "fits_per_scene": round(float(np.mean([r["fits"] for r in mine])), 1),
        "fit_ms": round(float(np.median(times)), 1) if times else None,
        "cpu_ms": round(float(np.median(cpu)), 1) if cpu else None,
        "seeds": [min(r["seed"] for r in mine), max(r["seed"] for r in mine)],
    }  # fmt: skip


def _scores(mine: Sequence[dict[str, Any]], prefix: str) -> dict[str, Any]:
    """Coverage, precision and median of the rows' figures named with ``prefix``,
    pooled as the module docstring says."""
    length = np.array([r["length_m"] for r in mine])
    fitted = np.array([r[prefix + "fitted_m"] for r in mine])
    coverage = np.array([r[prefix + "coverage"] for r in mine])
    precision = np.array([r[prefix + "precision"] for r in mine])
    medians = [r[prefix + "median_mm"] for r in mine if np.isfinite(r[prefix + "median_mm"])]
    return {
        "coverage": round(float(np.sum(length * coverage) / np.sum(length)), 3),
        "precision": round(float(np.sum(fitted * precision) / max(fitted.sum(), 1e-9)), 3),
        "median_mm": round(float(np.median(medians)), 2) if medians else None,
    }


def _run(args: argparse.Namespace) -> None:
    folder = Path(args.out)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{args.condition}_{args.first}_{args.last}.jsonl"
    with path.open("w") as f:
        for seed in range(args.first, args.last + 1):
            rows = scene_rows(
                args.condition, seed, union=args.union, only=args.sources, budgets=args.budgets
            )
            for row in rows:
                f.write(json.dumps(row) + "\n")
            f.flush()
            print(args.condition, seed, flush=True)


def side_by_side(table: Sequence[dict[str, Any]]) -> list[str]:
    """The summary as a markdown table, one row per condition and source: each figure
    for each budget in the order of BUDGETS (``view → reach → length``), "-" where the
    rows lack it."""
    keys = ("coverage", "precision", "kept_precision", "median_mm", "cpu_ms")
    lines = [
        "| condition | source | scenes | " + " | ".join(keys) + " |",
        "| --- | --- | --- |" + " --- |" * len(keys),
    ]
    for condition, source in itertools.product(CONDITIONS, SOURCES):
        pair = {
            r["budget"]: r for r in table if (r["condition"], r["source"]) == (condition, source)
        }
        if not pair:
            continue
        cells = [" → ".join(_cell(pair[b].get(k)) for b in BUDGETS if b in pair) for k in keys]
        scenes = "/".join(str(pair[b]["scenes"]) for b in BUDGETS if b in pair)
        lines.append(f"| {condition} | `{source}` | {scenes} | " + " | ".join(cells) + " |")
    return lines


def _cell(value: Any) -> str:
    return "-" if value is None else str(value)


def _table(args: argparse.Namespace) -> None:
    rows = [
        json.loads(line)
        for folder in args.folders
        for path in sorted(Path(folder).glob("*.jsonl"))
        for line in path.read_text().splitlines()
    ]
    table = summarise(rows)
    for line in side_by_side(table):
        print(line)
    if args.out:
        Path(args.out).write_text(json.dumps(table, indent=1) + "\n")


def main(argv: list[str] | None = None) -> None:
    """``run CONDITION FIRST LAST --out DIR`` or ``table DIR... [--out FILE]``."""
    parser = argparse.ArgumentParser(prog="python -m softarm.experiments.cane_sources")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="score every source on seeds FIRST..LAST")
    run.add_argument("condition", choices=CONDITIONS)
    run.add_argument("first", type=int)
    run.add_argument("last", type=int)
    run.add_argument("--out", required=True, help="folder for the rows (JSON lines)")
    run.add_argument("--union", action="store_true", help="score net|colour too")
    run.add_argument("--sources", nargs="+", choices=SOURCES, help="only these sources")
    run.add_argument(
        "--budgets", nargs="+", choices=tuple(BUDGETS), default=list(BUDGETS),
        help="only these budgets",
    )  # fmt: skip
    table = sub.add_parser("table", help="the summary of the rows in FOLDERS")
    table.add_argument("folders", nargs="+")
    table.add_argument("--out", help="the summary as JSON")
    args = parser.parse_args(argv)
    _run(args) if args.command == "run" else _table(args)


if __name__ == "__main__":
    main()
