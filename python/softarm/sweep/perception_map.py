"""The perception map of the daylight row (``softarm sweep SPEC`` with a
``[perception]`` spec, :mod:`.perception_spec`): every (cell, seed) is one task
(:func:`~softarm.sweep.perception_trial.run_perception_trial`), on Ray (a local Ray on
this machine's cores, or a cluster) or, without Ray, one after another in this process.

What it writes in OUT:

* ``cells/<trial_id>.json``: each finished trial's row, written as it finishes (the
  table ``--resume`` completes: it skips the trials there and reruns the failed ones);
* ``row_robustness.json``: each cell's figures pooled over its seeds
  (:func:`~softarm.sweep.perception_score.cell_summary`) with the spec;
* ``row_robustness.md``: the same as a Markdown table (:func:`markdown_table`);
* ``row_robustness_map.png``: the picture (:mod:`.perception_plot`).
"""

from __future__ import annotations

import json
import math
import signal
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from softarm.errors import ConfigError, MissingDependencyError
from softarm.sweep.perception_score import cell_summary
from softarm.sweep.perception_spec import CELL_KEYS, PerceptionSpec, PerceptionTrial

__all__ = ["MapOutcome", "markdown_table", "run_map", "summarise", "write_outputs"]

TrialFn = Callable[[PerceptionTrial], dict[str, Any]]


@dataclass
class MapOutcome:
    """What :func:`run_map` did: trials in the spec, skipped (done before), run now,
    failed now; on Ray or not, and its CPUs; interrupted by a signal."""

    total: int
    skipped: int = 0
    ran: int = 0
    failed: int = 0
    on_ray: bool = False
    cpus: float = math.nan
    wall_s: float = 0.0
    interrupted: bool = False
    signal: int | None = None


def _cells_dir(out: Path) -> Path:
    return out / "cells"


def _done(out: Path) -> dict[str, dict[str, Any]]:
    """trial id -> row of the trials finished in ``out``."""
    folder = _cells_dir(out)
    rows = {}
    for path in sorted(folder.glob("*.json")) if folder.is_dir() else []:
        try:
            row = json.loads(path.read_text())
        except (OSError, ValueError):
            continue  # half written when stopped: run it again
        rows[path.stem] = row
    return rows


def _write_row(out: Path, row: dict[str, Any]) -> None:
    folder = _cells_dir(out)
    folder.mkdir(parents=True, exist_ok=True)
    tmp = folder / f".{row['trial_id']}.tmp"
    tmp.write_text(json.dumps(row) + "\n")
    tmp.replace(folder / f"{row['trial_id']}.json")  # whole or absent, never half


def _want_ray(use_ray: bool | None) -> bool:
    if use_ray is False:
        return False
    from softarm.sweep._deps import require

    try:
        require("ray")
    except MissingDependencyError:
        if use_ray:
            raise
        return False  # as softarm.sweep.run: one trial after another in this process
    return True


def run_map(
    spec: PerceptionSpec,
    out: str | Path,
    *,
    use_ray: bool | None = None,
    address: str | None = None,
    cpus: int | None = None,
    resume: bool = False,
    trial_fn: TrialFn | None = None,
    on_trial: Callable[[dict[str, Any]], None] | None = None,
) -> MapOutcome:
    """Run every trial of ``spec`` not yet finished in ``out``.

    Args:
        use_ray: True: on Ray (the sweep extra needed); False: in this process; None:
            on Ray where it is installed, else in this process.
        address, cpus: a Ray cluster to join, or the local Ray's cores.
        resume: complete ``out``'s trials; without it a folder with trials is an error.
        trial_fn: the task's work (default ``run_perception_trial``; tests pass others).
        on_trial: called with each finished row.

    Raises:
        ConfigError: ``out`` holds trials and ``resume`` is False.
        MissingDependencyError: ``use_ray`` is True and Ray is not installed.
    """
    from softarm.sweep.perception_trial import run_perception_trial

    out = Path(out)
    done = _done(out)
    if done and not resume:
        raise ConfigError(
            f"--out {out}: holds trials of an earlier map; pass --resume to complete it "
            "or choose another directory"
        )
    finished = {k for k, r in done.items() if r.get("error") is None}
    trials = spec.trials()
    todo = [t for t in trials if t.trial_id not in finished]
    outcome = MapOutcome(len(trials), len(trials) - len(todo))
    fn = trial_fn or run_perception_trial

    def finish(row: dict[str, Any]) -> None:
        _write_row(out, row)
        outcome.ran += 1
        outcome.failed += row.get("error") is not None
        if on_trial is not None:
            on_trial(row)

    start = time.perf_counter()
    if todo and _want_ray(use_ray):
        outcome.on_ray = True
        _on_ray(todo, fn, finish, outcome, address, cpus)
    else:
        outcome.cpus = 1.0
        try:
            for trial in todo:
                finish(fn(trial))
        except KeyboardInterrupt:
            outcome.interrupted, outcome.signal = True, signal.SIGINT
    outcome.wall_s = round(time.perf_counter() - start, 1)
    return outcome


def _on_ray(
    todo: list[PerceptionTrial],
    fn: TrialFn,
    finish: Callable[[dict[str, Any]], None],
    outcome: MapOutcome,
    address: str | None,
    cpus: int | None,
) -> None:
    """The trials as Ray tasks (one CPU each), each row written as it comes back; Ctrl-C
    or SIGTERM cancels the rest and keeps what finished (as ``softarm sweep``)."""
    from softarm.sweep._deps import require
    from softarm.sweep.runner import _last_signal, _sigterm_as_interrupt, init_ray

    ray = require("ray")
    ours = not ray.is_initialized()
    _last_signal[0] = None
    pending: dict[Any, PerceptionTrial] = {}
    try:
        with _sigterm_as_interrupt() as rearm:
            init_ray(address, cpus)
            rearm()
            outcome.cpus = float(ray.cluster_resources().get("CPU", math.nan))
            task = ray.remote(num_cpus=1, max_retries=1, retry_exceptions=False)(fn)
            pending = {task.remote(t): t for t in todo}
            while pending:
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)
                for ref in ready:
                    trial = pending.pop(ref)
                    try:
                        row = ray.get(ref)
                    except ray.exceptions.RayError as exc:  # the worker died twice
                        first = (str(exc).strip().splitlines() or [""])[0]
                        row = {
                            "trial_id": trial.trial_id,
                            **_cell(trial),
                            "seed": trial.seed,
                            "error": f"{type(exc).__name__}: {first}",
                        }
                    finish(row)
    except KeyboardInterrupt as exc:
        for ref in pending:
            ray.cancel(ref, force=True)
        outcome.interrupted = True
        outcome.signal = getattr(exc, "signum", None) or _last_signal[0] or signal.SIGINT
    finally:
        if ours and ray.is_initialized():
            ray.shutdown()


def _cell(trial: PerceptionTrial) -> dict[str, str]:
    return dict(zip(CELL_KEYS, trial.cell, strict=True))


def summarise(spec: PerceptionSpec, out: str | Path) -> dict[str, Any]:
    """The map's document: the spec, and each cell's figures pooled over the seeds of
    the trials finished in ``out`` (cells in the spec's order)."""
    rows = _done(Path(out))
    wanted = {t.trial_id for t in spec.trials()}
    by_cell: dict[tuple[str, ...], list[dict[str, Any]]] = {c: [] for c in spec.cells()}
    for trial_id, row in rows.items():
        if trial_id in wanted:
            by_cell[tuple(row[k] for k in CELL_KEYS)].append(row)
    setup = asdict(spec)
    setup.pop("source")
    good = [r for r in rows.values() if r.get("error") is None and r["trial_id"] in wanted]
    return {
        "what": "perception per frame on the daylight row: C1's stereo pair, the arm out of "
        "view, scored against the renderer's ground truth (softarm.sweep.perception_score)",
        "spec": setup,
        "trials": len(good),
        "cpu_s_per_trial": round(sum(r["cpu_s"] for r in good) / len(good), 1) if good else None,
        "cells": [
            {**dict(zip(CELL_KEYS, cell, strict=True)), **cell_summary(rs, spec.detectors)}
            for cell, rs in by_cell.items()
        ],
    }


def _f(value: Any, digits: int = 2) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def markdown_table(doc: dict[str, Any]) -> str:
    """The map as Markdown: one row per cell; per detector ripe precision / ripe recall /
    located (share of ripe targets placed by stereo within 10 mm); the colour detector's
    median stereo error and its wrong ripe calls (on look-alikes / turning fruit / else);
    the cane map's coverage / precision / median distance (mm)."""
    detectors = doc["spec"]["detectors"]
    head = [
        "look",
        "camera",
        "look-alikes",
        "fruit",
        "ripe targets",
        *(f"{d}: P / R / loc" for d in detectors),
        f"{detectors[0]} stereo mm",
        f"{detectors[0]} wrong ripe: alike / turning / else",
        "canes: cov / prec / mm",
    ]
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for c in doc["cells"]:
        dets = c["detectors"]
        cells = [
            f"{_f(dets[d]['ripe_precision'])} / {_f(dets[d]['recall_ripe'])} / "
            f"{_f(dets[d].get('located'))}"
            for d in detectors
        ]
        first = dets[detectors[0]].get("stereo_median_mm")
        wrong = dict(dets[detectors[0]].get("wrong_ripe_on", {}))
        alike, turning = wrong.pop("clutter", 0), wrong.pop("turning", 0)
        canes = c.get("canes")
        cane = (
            "–"
            if canes is None
            else (
                f"{_f(canes['coverage'])} / {_f(canes['precision'])} / {_f(canes['median_mm'], 1)}"
            )
        )
        row = [
            c["look"],
            c["effects"],
            c["lookalikes"],
            c["fruit"],
            str(c["ripe_targets"]),
            *cells,
            _f(first, 1),
            f"{alike} / {turning} / {sum(wrong.values())}",
            cane,
        ]
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines) + "\n"


def _dumps(doc: dict[str, Any]) -> str:
    """``doc`` as JSON, one line per cell (small, and a cell's change one line of diff)."""
    head = json.dumps({k: v for k, v in doc.items() if k != "cells"}, indent=1)
    cells = ",\n  ".join(json.dumps(c, separators=(",", ":")) for c in doc["cells"])
    return f'{head[:-2]},\n "cells": [\n  {cells}\n ]\n}}\n'


def write_outputs(doc: dict[str, Any], out: str | Path, picture: bool = True) -> list[Path]:
    """``row_robustness.json``, ``.md`` and (``picture``) ``row_robustness_map.png`` in
    ``out``; returns their paths."""
    from softarm.files import write_text

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / "row_robustness.json", out / "row_robustness.md"]
    write_text(paths[0], _dumps(doc), "out")
    write_text(paths[1], markdown_table(doc), "out")
    if picture:
        from softarm.sweep.perception_plot import plot_map

        paths.append(out / "row_robustness_map.png")
        plot_map(doc, paths[2])
    return paths
