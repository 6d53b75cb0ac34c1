"""The markerless harvest's goals from its reports (``softarm harvest --sim --world bush
--report``, or ``--world row``): harvested share of the ripe berries in reach, the ripe
ones never mapped, unripe (and turning) picked, true fine-positioning error (mean and
p95), contacts and the smallest cane gap, the cane map; and the wall time per berry
beside the tag world's on the same seeds when its reports and times are given.

    python -m softarm.experiments.bush_harvest runs/bush_harvest_700-709

``--run FIRST LAST BUSH_DIR TAG_DIR`` makes those folders first: for each seed, the
bush world's harvest and then the tag world's on the same seed (so the two share the
machine's load), each timed as a whole process, their reports and ``wall_times.txt``
written (``--berries``, 8 by default; ``--no-survey``: the bush world without C2's
cane survey, C1's canes only; ``--jobs N``: N seeds at once, on a machine with the
cores for it; ``--world row --look L``: the daylight row in look L instead of the bush;
TAG_DIR ``-``: no tag world)::

    MUJOCO_GL=egl python -m softarm.experiments.bush_harvest --run 770 779 \
        runs/bush_harvest_770-779 runs/tag_harvest_770-779
    MUJOCO_GL=egl python -m softarm.experiments.bush_harvest --run 90120 90125 \
        runs/row_sun_90120-90125 - --world row --look sun --berries 4
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

from softarm.errors import InputError
from softarm.perception.cane_metrics import cane_map_error
from softarm.sim.world import WorldName

__all__ = ["summarise"]

#: A berry with less than this share of it in view of C1 counts as hidden from C1.
HIDDEN_SHARE = 0.1


def summarise(reports: list[dict[str, Any]]) -> dict[str, float]:
    """Pooled figures over ``reports`` (one per bush)."""
    ripe = sum(r["ripe_in_reach"] for r in reports)
    errors = [b["true_position_error_mm"] for r in reports for b in r["berries"] if b["harvested"]]
    gaps = [r["min_branch_gap_m"] for r in reports if r.get("min_branch_gap_m") is not None]
    # A bush whose canes in reach were all missed has no distances (None): its coverage
    # still counts.
    maps = [r["cane_map"] for r in reports]
    medians = [m["median_mm"] for m in maps if m["median_mm"] is not None]
    p95s = [m["p95_mm"] for m in maps if m["p95_mm"] is not None]
    return {
        "bushes": len(reports),
        "ripe_in_reach": ripe,
        "ripe_harvested": sum(r["ripe_harvested"] for r in reports),
        "harvested_share": sum(r["ripe_harvested"] for r in reports) / max(ripe, 1),
        "ripe_never_mapped": sum(r["ripe_never_mapped"] for r in reports),
        "never_mapped_hidden_from_c1": _hidden_from_c1(reports),
        "unripe_picked": sum(r["unripe_picked"] for r in reports),
        "mean_true_fine_error_mm": statistics.fmean(errors) if errors else float("nan"),
        "p95_true_fine_error_mm": float(np.percentile(errors, 95)) if errors else float("nan"),
        "contact_steps": sum(r["branch_contact_steps"] for r in reports),
        "runs_with_contact": sum(r["branch_contact_steps"] > 0 for r in reports),
        "min_cane_gap_mm": 1e3 * min(gaps) if gaps else float("nan"),
        "cane_median_mm": statistics.median(medians) if medians else float("nan"),
        "cane_p95_mm": statistics.median(p95s) if p95s else float("nan"),
        "cane_coverage": _length_weighted_coverage(reports),
        "cane_coverage_per_bush": statistics.fmean(m["coverage"] for m in maps),
        "cane_precision": _mean_precision(maps),
        "sim_s_per_berry": sum(r["sim_time_s"] for r in reports)
        / max(sum(len(r["berries"]) for r in reports), 1),
    }


def _hidden_from_c1(reports: list[dict[str, Any]]) -> float:
    """How many ripe berries the map never held were under ``HIDDEN_SHARE`` in view of
    C1 from where it looks (hidden from C1; C2 places only fruit C1 glimpsed, so these
    were hidden from both cameras as the harvest uses them); NaN when older reports do
    not record the shares."""
    if any("ripe_never_mapped_c1_share" not in r for r in reports):
        return float("nan")
    shares = [s for r in reports for s in r["ripe_never_mapped_c1_share"]]
    return float(sum(s < HIDDEN_SHARE for s in shares))


def _mean_precision(maps: list[dict[str, Any]]) -> float:
    """The maps' mean precision (the share of fitted length near a true cane); NaN when
    older reports do not record it."""
    if any("precision" not in m for m in maps):
        return float("nan")
    return statistics.fmean(float(m["precision"]) for m in maps)


def _length_weighted_coverage(reports: list[dict[str, Any]]) -> float:
    """The share of all the bushes' true cane length in the workspace that the maps
    cover (the goal's measure: each bush weighs by its length there, so a bush with a
    few centimetres of cane in reach counts for a few centimetres)."""
    lengths = [_cane_length(r) for r in reports]
    covered = sum(
        float(r["cane_map"]["coverage"]) * n for r, n in zip(reports, lengths, strict=True)
    )
    return covered / max(sum(lengths), 1e-12)


def _cane_length(report: dict[str, Any]) -> float:
    """The true cane length (m) in the workspace: the report's, else from the canes
    its header records."""
    if "length_m" in report["cane_map"]:
        return float(report["cane_map"]["length_m"])
    canes = [SimpleNamespace(coeffs=np.asarray(c)) for c in report["header"]["world"]["canes"]]
    return float(cane_map_error([], canes)["length_m"])


def wall_per_berry(folder: Path) -> float:
    """Whole-process wall seconds per berry attempted, from ``wall_times.txt`` (one
    ``SEED wall SECONDS`` line per run, as /usr/bin/time -f writes them)."""
    seconds = [
        float(line.split()[-1])
        for line in (folder / "wall_times.txt").read_text().splitlines()
        if " wall " in line
    ]
    attempted = sum(len(r["berries"]) for r in _reports(folder))
    return sum(seconds) / max(attempted, 1)


def _reports(folder: Path) -> list[dict[str, Any]]:
    """The harvest reports (``r*.json``) in ``folder``.

    Raises:
        InputError: ``folder`` holds none (or is not a folder)."""
    paths = sorted(folder.glob("r*.json")) if folder.is_dir() else []
    if not paths:
        raise InputError(f"{folder}: no harvest reports (r*.json) there")
    return [json.loads(p.read_text()) for p in paths]


def run_pair(
    seeds: range,
    bush_dir: Path,
    tag_dir: Path | None,
    berries: int = 8,
    survey: bool = True,
    jobs: int = 1,
    look: str | None = None,
) -> None:
    """Harvest each seed in the bush world (without C2's cane survey unless ``survey``;
    in the daylight row in ``look`` where one is given), then in the tag world unless
    ``tag_dir`` is None, timing each whole process (``python -m softarm harvest --sim
    ...``); reports and wall times into the folders. ``jobs`` seeds run at once (each
    seed's worlds one after the other, so they share the load)."""
    worlds: list[tuple[Path, list[str]]] = [(bush_dir, _rendered_args(survey, look))]
    if tag_dir is not None:
        worlds.append((tag_dir, []))
    for folder, _ in worlds:
        folder.mkdir(parents=True, exist_ok=True)
    lock = threading.Lock()

    def one_seed(seed: int) -> None:
        for folder, world in worlds:
            report = folder / f"r{seed}.json"
            command = [sys.executable, "-m", "softarm", "harvest", "--sim", *world,
                       "--berries", str(berries), "--seed", str(seed),
                       "--report", str(report), "--quiet"]  # fmt: skip
            start = time.monotonic()
            subprocess.run(command, check=False, stdout=subprocess.DEVNULL)
            wall = time.monotonic() - start
            with lock, (folder / "wall_times.txt").open("a") as f:
                f.write(f"{seed} wall {wall:.2f}\n")

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        list(pool.map(one_seed, seeds))


def _rendered_args(survey: bool, look: str | None) -> list[str]:
    """The harvest's world options: the bush, or the daylight row in ``look``."""
    world = ["--world", "bush"] if look is None else ["--world", "row", "--look", look]
    return world + ([] if survey else ["--no-survey"])


def _option(argv: list[str], name: str, default: str | None) -> str | None:
    """The value after ``name`` in ``argv``, else ``default``."""
    return argv[argv.index(name) + 1] if name in argv else default


def main(argv: list[str]) -> None:
    """Print the pooled figures of each folder of reports on the command line (after
    making them, with ``--run``)."""
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        return
    if argv[:1] == ["--run"]:
        berries = int(_option(argv, "--berries", "8") or 8)
        jobs = int(_option(argv, "--jobs", "1") or 1)
        look = _option(argv, "--look", None)
        world_name = _option(argv, "--world", "bush")
        if world_name not in ("bush", "row"):
            raise InputError(f"--world must be bush or row, got {world_name!r}")
        world = WorldName(world_name)
        if (world is WorldName.ROW) != (look is not None):
            raise InputError("--world row and --look: both or neither")
        first, last, bush_dir, tag_dir = argv[1:5]
        seeds = range(int(first), int(last) + 1)
        tags = None if tag_dir == "-" else Path(tag_dir)
        survey = "--no-survey" not in argv
        run_pair(seeds, Path(bush_dir), tags, berries, survey, jobs, look)
        argv = [bush_dir] + ([] if tags is None else [tag_dir])
    for name in argv:
        folder = Path(name)
        reports = _reports(folder)
        bush = all(r.get("world") in (WorldName.BUSH, WorldName.ROW) for r in reports)
        figures: dict[str, float] = summarise(reports) if bush else {"bushes": len(reports)}
        if (folder / "wall_times.txt").exists():
            figures["wall_s_per_berry"] = wall_per_berry(folder)
        print(folder.name, json.dumps({k: round(v, 3) for k, v in figures.items()}))


if __name__ == "__main__":
    try:
        main(sys.argv[1:])
    except InputError as exc:
        sys.exit(f"bush_harvest: {exc}")
