"""One sweep trial (a plant point harvested on one seed's bush) and its rows of results.

Plain Python, no Ray: the Ray task in :mod:`softarm.sweep.runner` calls
:func:`run_trial_rows`, which never raises — a trial that fails becomes one row with its
``error`` — so one bad plant point never stops a sweep.
"""

from __future__ import annotations

import math
import socket
import time
import traceback
from typing import Any

from softarm.sweep.spec import TrialSpec

__all__ = ["BERRY_COLUMNS", "error_row", "run_trial", "run_trial_rows"]

#: Per-berry result columns, in table order (after ``trial_id``, ``seed`` and the swept keys).
BERRY_COLUMNS: tuple[str, ...] = (
    "berry",
    "tag_id",
    "harvested",
    "true_position_error_mm",
    "orientation_error_deg",
    "true_orientation_error_deg",
    "position_error_mm",
    "duration_s",
    "fault",
    "branch_contact_steps",
    "min_branch_gap_m",
    "stopped",
    "berries_per_hour",
    "sim_s",
    "error",
    "wall_s",
    "cpu_s",
    "node",
)


def _single_threaded() -> None:
    """One trial per core: keep OpenCV from spreading one trial's images over every core
    (it would make the one-core baseline use all of them and scaling look worse)."""
    try:
        import cv2

        cv2.setNumThreads(1)
    except ImportError:  # the rig will say so when it needs it
        pass


def run_trial(trial: TrialSpec) -> Any:
    """Build the simulated rig for ``trial`` and harvest its bush; returns the report."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.stops import vents_on_stop
    from softarm.sweep.plant_keys import plant_config

    plant = plant_config(trial.plant)
    options = SimRigOptions(
        n_berries=trial.berries, seed=trial.seed, plant=plant, gains=trial.gains, **trial.rig
    )
    rig = build_sim_rig(options)
    # A worker stopped mid-trial (Ray's SIGTERM handler exits, a cancel raises
    # KeyboardInterrupt) vents the arm and records why, as `softarm harvest` does.
    with vents_on_stop(rig.machine.actuator.vent, rig.machine.log):
        return rig.run()


def _key(trial: TrialSpec) -> dict[str, Any]:
    from softarm.sweep.plant_keys import column_value

    plant = {k: column_value(v) for k, v in trial.plant.items()}
    return {"trial_id": trial.trial_id, "seed": trial.seed, **plant}


def error_row(trial: TrialSpec, error: str, wall_s: float = math.nan) -> dict[str, Any]:
    """The single row of a trial that failed (its berries unknown)."""
    row: dict[str, Any] = dict.fromkeys(BERRY_COLUMNS)
    row.update(_key(trial), error=error, wall_s=wall_s, node=socket.gethostname())
    return row


def run_trial_rows(trial: TrialSpec, single_threaded: bool = True) -> list[dict[str, Any]]:
    """One row per berry of ``trial`` (see :data:`BERRY_COLUMNS`), or one error row;
    ``single_threaded``: OpenCV on one thread (a Ray worker, one trial per core)."""
    if single_threaded:
        _single_threaded()
    start, cpu_start = time.perf_counter(), time.process_time()
    try:
        report = run_trial(trial).to_dict()
    except Exception as exc:  # recorded in the table; the sweep goes on
        last = traceback.extract_tb(exc.__traceback__)[-1]
        where = f" ({last.filename.rsplit('/', 1)[-1]}:{last.lineno})"
        return [
            error_row(trial, f"{type(exc).__name__}: {exc}{where}", time.perf_counter() - start)
        ]
    wall = time.perf_counter() - start
    cpu = time.process_time() - cpu_start  # this process's CPU time: throughput on a busy host
    rate = report.get("rate") or {}
    rows = []
    for i, b in enumerate(report["berries"]):
        rows.append(
            {
                **_key(trial),
                "berry": i,
                "tag_id": b["tag_id"],
                "harvested": bool(b["harvested"]),
                "true_position_error_mm": b.get("true_position_error_mm"),
                "orientation_error_deg": b.get("orientation_error_deg"),
                "true_orientation_error_deg": b.get("true_orientation_error_deg"),
                "position_error_mm": b.get("position_error_mm"),
                "duration_s": b.get("duration_s"),
                "fault": b.get("fault"),
                # Trial-level figures (the whole bush), repeated on each of its berries.
                "branch_contact_steps": report.get("branch_contact_steps"),
                "min_branch_gap_m": report.get("min_branch_gap_m"),
                "stopped": report.get("stopped"),
                # The bush's rate (softarm.harvest.records.rate): harvested per hour of simulated
                # time, and that time, survey, moves and way home included.
                "berries_per_hour": rate.get("berries_per_hour"),
                "sim_s": rate.get("total_s"),
                "error": None,
                "wall_s": wall,
                "cpu_s": cpu,
                "node": socket.gethostname(),
            }
        )
    return rows
