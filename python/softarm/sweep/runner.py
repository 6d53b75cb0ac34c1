"""Runs a sweep on Ray: every (plant point, seed) is one task; results stream to the table
as tasks finish; Ctrl-C or SIGTERM leaves every finished trial on disk and Ray shut down.

Failure handling:

* a trial that raises is caught inside the task (:func:`~softarm.sweep.trial.run_trial_rows`)
  and recorded as one row with its ``error``; the sweep goes on;
* a worker process that dies (killed, out of memory) makes Ray retry the task
  ``max_retries`` times; if it dies again the trial is recorded as failed;
* ``--resume`` skips the trials that ran and runs again those recorded as failed.
"""

from __future__ import annotations

import logging
import math
import os
import signal
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softarm.errors import ConfigError
from softarm.sweep._deps import require
from softarm.sweep.spec import SweepSpec, TrialSpec
from softarm.sweep.table import ResultsTable, results_schema
from softarm.sweep.trial import error_row, run_trial_rows

__all__ = ["SweepOutcome", "init_ray", "run_sweep"]

TrialFn = Callable[[TrialSpec], list[dict[str, Any]]]


@dataclass
class SweepOutcome:
    """What a call of :func:`run_sweep` did."""

    table: Path
    total: int  # trials in the spec
    skipped: int  # already in the table (resume)
    ran: int  # finished now, including failed
    failed: int  # recorded with an error now
    berries: int  # berry rows written now
    wall_s: float  # from the first task submitted to the last one finished
    interrupted: bool = False
    signal: int | None = None  # the signal that interrupted it (SIGINT, SIGTERM)
    cpus: float = math.nan  # CPUs of the Ray cluster used
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def berries_per_hour(self) -> float:
        return 3600.0 * self.berries / self.wall_s if self.wall_s > 0 else math.nan


def init_ray(address: str | None = None, cpus: int | None = None) -> bool:
    """Start a private local Ray (all cores, or ``cpus``) or join the cluster at
    ``address``; returns False (and does nothing) if Ray is already initialised."""
    ray = require("ray")
    if ray.is_initialized():
        return False
    # Quiet and quick: no dashboard, worker output not echoed (errors go in the table).
    kwargs: dict[str, Any] = dict(
        include_dashboard=False,
        log_to_driver=False,
        logging_level=logging.ERROR,  # not the token-auth notice on every start
        ignore_reinit_error=True,
    )
    if address:
        if cpus is not None:
            raise ConfigError("--cpus: only for a local Ray; a cluster has its own CPUs")
        ray.init(address=address, **kwargs)
    else:
        # "local": always a fresh private instance, never someone's `ray start` cluster.
        ray.init(address="local", num_cpus=cpus, **kwargs)
    return True


#: The last SIGTERM our handler saw (see :func:`_sigterm_as_interrupt`).
_last_signal: list[int | None] = [None]


class _Stopped(KeyboardInterrupt):
    """SIGTERM, taking the Ctrl-C path."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"stopped by {signal.Signals(signum).name}")
        self.signum = signum


@contextmanager
def _sigterm_as_interrupt() -> Iterator[Callable[[], None]]:
    """SIGTERM (a batch system stopping the job) takes the Ctrl-C path. ``ray.init``
    installs its own SIGTERM handler (exit at once): call the yielded function after it
    to take SIGTERM back."""

    def handler(signum: int, frame: object) -> None:
        # Remember it: inside ray.wait Ray turns any exception from a signal handler
        # into a plain KeyboardInterrupt.
        _last_signal[0] = signum
        raise _Stopped(signum)

    def arm() -> None:
        signal.signal(signal.SIGTERM, handler)

    try:
        previous = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread: leave signals alone
        yield lambda: None
        return
    try:
        yield arm
    finally:
        signal.signal(signal.SIGTERM, previous)


def _progress(total: int, enabled: bool) -> Any:
    tqdm = require("tqdm").tqdm
    return tqdm(total=total, unit="berry", disable=None if enabled else True, file=sys.stderr,
                dynamic_ncols=True, smoothing=0.05, desc="sweep")  # fmt: skip


def run_sweep(
    spec: SweepSpec,
    out: str | Path,
    *,
    address: str | None = None,
    resume: bool = False,
    cpus: int | None = None,
    progress: bool = True,
    trial_fn: TrialFn | None = None,
    max_retries: int = 1,
    on_trial: Callable[[TrialSpec, list[dict[str, Any]]], None] | None = None,
) -> SweepOutcome:
    """Run every trial of ``spec`` not yet in ``out``'s table on Ray.

    Args:
        spec: the sweep.
        out: results directory (``results.parquet``, ``parts/``).
        address: a Ray cluster to join; None starts a local one (``cpus`` cores, all by
            default). If Ray is already initialised it is used as it is and left running.
        resume: continue the table in ``out``; without it an existing table is an error.
        progress: show a progress bar with an ETA (stderr).
        trial_fn: the task's work (default :func:`run_trial_rows`; tests pass others).
        max_retries: times Ray reruns a task whose worker died.
        on_trial: called in the driver after each trial is written.

    Raises:
        ConfigError: ``out`` holds results and ``resume`` is False.
    """
    ray = require("ray")
    trials = spec.trials()
    table = ResultsTable(out, results_schema(spec.plant), [t.trial_id for t in trials])
    if table.exists() and not resume:
        raise ConfigError(
            f"--out {out}: holds results of an earlier sweep; pass --resume to complete it "
            "or choose another directory"
        )
    if resume:
        table.adopt_results()
    done = table.finished() if resume else {}
    todo = [t for t in trials if not done.get(t.trial_id, False)]
    outcome = SweepOutcome(table.path, len(trials), len(trials) - len(todo), 0, 0, 0, 0.0)
    ours = not ray.is_initialized()  # a Ray we start, we stop
    _last_signal[0] = None
    try:
        with _sigterm_as_interrupt() as rearm:
            if todo:
                try:
                    init_ray(address, cpus)
                except SystemExit as exc:
                    # ray.init's own SIGTERM handler (active while it starts) exits with
                    # the signal number: take the same path as a SIGTERM after it.
                    if exc.code == signal.SIGTERM:
                        raise _Stopped(signal.SIGTERM) from None
                    raise
                rearm()
                outcome.cpus = float(ray.cluster_resources().get("CPU", math.nan))
                _drive(ray, todo, table, outcome, progress, trial_fn, max_retries, on_trial)
    except KeyboardInterrupt as exc:
        outcome.interrupted = True
        outcome.signal = getattr(exc, "signum", None) or _last_signal[0] or signal.SIGINT
    finally:
        table.flush()
        if ours and ray.is_initialized():
            ray.shutdown()
    return outcome


def _drive(
    ray: Any,
    todo: list[TrialSpec],
    table: ResultsTable,
    outcome: SweepOutcome,
    progress: bool,
    trial_fn: TrialFn | None,
    max_retries: int,
    on_trial: Callable[[TrialSpec, list[dict[str, Any]]], None] | None,
) -> None:
    task = ray.remote(num_cpus=1, max_retries=max_retries, retry_exceptions=False)(
        trial_fn or run_trial_rows
    )
    # Ray queues the tasks and runs one per free CPU; the driver only waits and writes.
    pending = {task.remote(t): t for t in todo}
    start = time.perf_counter()
    harvested = 0
    bar = _progress(sum(t.berries for t in todo), progress)
    try:
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)
            for ref in ready:
                trial = pending.pop(ref)
                try:
                    rows = ray.get(ref)
                except ray.exceptions.RayError as exc:  # worker died after its retries
                    first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
                    rows = [error_row(trial, f"{type(exc).__name__}: {first}")]
                table.add(trial.trial_id, rows)
                outcome.ran += 1
                failed = any(r["error"] is not None for r in rows)
                outcome.failed += failed
                outcome.berries += 0 if failed else len(rows)
                harvested += sum(bool(r["harvested"]) for r in rows)
                outcome.wall_s = time.perf_counter() - start
                bar.update(trial.berries)
                bar.set_postfix(harvested=f"{harvested}/{outcome.berries}",
                                failed=outcome.failed, refresh=False)  # fmt: skip
                if on_trial is not None:
                    on_trial(trial, rows)
    except KeyboardInterrupt:
        # Stop the queued and running tasks now (force: kill their workers) instead of
        # leaving them to finish into a driver that is gone.
        for ref in pending:
            ray.cancel(ref, force=True)
        raise
    finally:
        bar.close()


def cpu_count() -> int:
    """The cores this process may use (the default size of a local Ray)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
