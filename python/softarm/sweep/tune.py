"""Gain tuning with Ray Tune: Optuna's TPE sampler (``ray.tune.search.optuna``) searches
the closed-loop resolver's gains; each candidate harvests every (plant point, seed) of the
spec and is scored by success first, cycle time second.

Score (maximised)::

    score = harvested fraction - 1e-4 * mean simulated seconds per berry

One berry in a thousand outweighs 10 s of cycle time per berry, so between candidates that
harvest differently the better harvester always wins, and cycle time decides among those
that harvest alike. A trial that fails counts all its berries as lost.

The search starts from the current gains (Optuna's ``points_to_evaluate``), so on the
tuning plants and seeds the result is never worse than the defaults. Tune on seeds you
will not report: the project keeps 500-599 held out.
"""

from __future__ import annotations

import math
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softarm.errors import ConfigError
from softarm.formatting import plural
from softarm.sweep._deps import require
from softarm.sweep.gains_file import gains_from, write_gains
from softarm.sweep.runner import init_ray
from softarm.sweep.spec import SweepSpec, TrialSpec, TuneRange
from softarm.sweep.trial import run_trial_rows

__all__ = ["DEFAULT_SPACE", "TuneOutcome", "run_tune", "score_rows"]

#: Seconds of cycle time worth one unit of harvested fraction (see the module docstring).
CYCLE_WEIGHT = 1e-4

#: The default search space: the hybrid closed loop's step gain α, orientation weight γ₄,
#: joint-limit weight γ₅ (eq. 20), the smooth schedule's switch distance, the damping of
#: the pseudo-inverses and the step cap. Ranges bracket the blackberry defaults.
DEFAULT_SPACE: dict[str, TuneRange] = {
    "hybrid_alpha": TuneRange(0.05, 0.6, log=True),
    "hybrid_orientation": TuneRange(0.2, 1.0),
    "hybrid_gamma": TuneRange(-2e-5, 0.0),
    "hybrid_switch": TuneRange(0.01, 0.15, log=True),
    "damping": TuneRange(0.005, 0.1, log=True),
    "max_step": TuneRange(0.001, 0.01, log=True),
}

TrialFn = Callable[[TrialSpec], list[dict[str, Any]]]


def score_rows(rows: list[dict[str, Any]], berries_expected: int) -> dict[str, float]:
    """Metrics of a candidate from its result rows (berries of failed trials are lost)."""
    ran = [r for r in rows if r["error"] is None]
    harvested = sum(bool(r["harvested"]) for r in ran)
    durations = [r["duration_s"] for r in ran if r["duration_s"] is not None]
    errors = [r["true_position_error_mm"] for r in ran
              if r["harvested"] and r["true_position_error_mm"] is not None]  # fmt: skip
    success = harvested / berries_expected if berries_expected else 0.0
    cycle = sum(durations) / len(durations) if durations else math.inf
    return {
        "score": success - CYCLE_WEIGHT * (cycle if math.isfinite(cycle) else 1e3),
        "success": success,
        "cycle_s": cycle if math.isfinite(cycle) else float("nan"),
        "mean_error_mm": sum(errors) / len(errors) if errors else float("nan"),
        "failed_trials": float(len({r["trial_id"] for r in rows if r["error"] is not None})),
    }


@dataclass
class TuneOutcome:
    """The best gains found and every candidate's metrics."""

    gains: dict[str, Any]
    metrics: dict[str, float]
    baseline: dict[str, float] | None
    candidates: list[dict[str, Any]] = field(default_factory=list)


def _domain(tune: Any, r: TuneRange) -> Any:
    if r.choices is not None:
        return tune.choice(list(r.choices))
    return (tune.loguniform if r.log else tune.uniform)(r.low, r.high)


def _inside(value: Any, r: TuneRange) -> bool:
    if r.choices is not None:
        return value in r.choices
    return isinstance(value, int | float) and r.low <= value <= r.high


def run_tune(
    spec: SweepSpec,
    out: str | Path,
    *,
    address: str | None = None,
    cpus: int | None = None,
    samples: int | None = None,
    progress: bool = True,
    trial_fn: TrialFn | None = None,
) -> TuneOutcome:
    """Search the gains of ``spec.tune.space`` (default :data:`DEFAULT_SPACE`) on Ray Tune
    and write the best as a ``[gains]`` file at ``out``. The progress bar (``progress``,
    on a terminal) counts the candidates' trials (each a (plant point, seed) harvest) as
    they finish, so its ETA shows from the first one."""
    ray = require("ray")
    tune = require("ray.tune")
    space = spec.tune.space or DEFAULT_SPACE
    n_samples = samples if samples is not None else spec.tune.samples
    if n_samples < 1:
        raise ConfigError(f"--samples: must be >= 1, got {n_samples}")
    base = gains_from(spec.gains).as_dict()
    start_point = {k: base[k] for k in space}
    points = [start_point] if all(_inside(start_point[k], r) for k, r in space.items()) else []
    objective = _objective(tune, spec, trial_fn or run_trial_rows)
    _quiet_tune()
    started = init_ray(address, cpus)
    storage = Path(tempfile.mkdtemp(prefix="softarm-tune-"))
    try:
        bar = _bar_callback(tune, n_samples, len(spec.trials()), progress)
        search = _Search(space, n_samples, spec.tune.seed, points)
        grid = _tuner(tune, objective, search, storage, bar).fit()
        candidates = _candidates(grid)
    finally:
        shutil.rmtree(storage, ignore_errors=True)
        if started:
            ray.shutdown()
    candidates.sort(key=lambda c: c["score"], reverse=True)
    best = candidates[0]
    gains = {**spec.gains, **{k: best[k] for k in space}}
    metrics = {k: best[k] for k in METRICS}
    baseline = next((c for c in candidates if all(c[k] == start_point[k] for k in space)), None)
    write_gains(out, gains_from(gains), _header(spec, n_samples, metrics, baseline))
    return TuneOutcome(gains, metrics, baseline, candidates)


#: A candidate's metrics kept in the outcome (score_rows' less the failed trials).
METRICS = ("score", "success", "cycle_s", "mean_error_mm")
#: The field of a candidate's report that counts its trials done (the progress bar's).
TRIALS_DONE = "trials_done"


def _objective(tune: Any, spec: SweepSpec, work: TrialFn) -> Callable[[dict[str, Any]], None]:
    """One candidate: every plant point and seed, in this worker, one after another. It
    reports after each trial (the score so far, the trials not yet run counting as lost),
    so the driver's bar moves while it runs; the last report is the candidate's score."""
    expected = sum(t.berries for t in spec.trials())

    def objective(config: dict[str, Any]) -> None:
        rows: list[dict[str, Any]] = []
        for i, t in enumerate(spec.with_gains(config).trials(), start=1):
            rows += work(t)
            tune.report({**score_rows(rows, expected), TRIALS_DONE: i})

    return objective


def _quiet_tune() -> None:
    """Ray Tune's and Optuna's console output off, and Ctrl-C left to the command line."""
    # Tune's own console tables and Optuna's per-trial log lines: the bar says enough.
    os.environ.setdefault("RAY_AIR_NEW_OUTPUT", "0")
    # Ctrl-C stops the search: Ray Tune's own SIGINT handler would instead end it quietly
    # and return the candidates so far (a gains file from a cut search, or exit 2 with
    # none); KeyboardInterrupt reaches the command line, which exits 130, no gains written.
    os.environ.setdefault("TUNE_DISABLE_SIGINT_HANDLER", "1")
    optuna = require("optuna")
    optuna.logging.set_verbosity(optuna.logging.WARNING)


@dataclass(frozen=True)
class _Search:
    """What the search explores: the space, how many candidates, the sampler's seed and
    the points tried first."""

    space: dict[str, TuneRange]
    samples: int
    seed: int
    points: list[dict[str, Any]]


def _tuner(tune: Any, objective: Any, search: _Search, storage: Path, bar: Any) -> Any:
    """The Tuner: Optuna's TPE, as many candidates at once as Ray has cores."""
    ray = require("ray")
    optuna_search = require("ray.tune.search.optuna")
    from ray.tune.search import ConcurrencyLimiter

    concurrency = max(1, int(ray.cluster_resources().get("CPU", 1)))
    searcher = optuna_search.OptunaSearch(
        metric="score", mode="max", seed=search.seed, points_to_evaluate=search.points or None
    )
    return tune.Tuner(
        tune.with_resources(objective, {"cpu": 1}),
        param_space={k: _domain(tune, r) for k, r in search.space.items()},
        tune_config=tune.TuneConfig(
            search_alg=ConcurrencyLimiter(searcher, max_concurrent=concurrency),
            metric="score",
            mode="max",
            num_samples=search.samples,
        ),
        run_config=tune.RunConfig(
            name="softarm-tune",
            storage_path=str(storage),
            verbose=0,
            callbacks=[bar],
            failure_config=tune.FailureConfig(max_failures=1),
        ),
    )


def _candidates(grid: Any) -> list[dict[str, Any]]:
    """Each finished candidate's gains and metrics (its last report: every trial run)."""
    candidates = []
    for res in grid:
        if res.error is None and res.metrics and "score" in res.metrics:
            candidates.append({**res.config, **{k: res.metrics[k] for k in METRICS}})
    if not candidates:
        errors = [str(res.error).splitlines()[0] for res in grid if res.error is not None]
        raise ConfigError(f"tune: no candidate finished ({errors[0] if errors else 'none ran'})")
    return candidates


def _header(spec: SweepSpec, samples: int, m: dict[str, float], base: dict[str, Any] | None) -> str:
    lines = [
        f"softarm tune {spec.source}: {plural(samples, 'candidate')}, Optuna TPE "
        f"(seed {spec.tune.seed})",
        f"plants: {dict(spec.plant) or 'default'}; seeds {list(spec.seeds)}; "
        f"{plural(spec.berries, 'berry')} per bush",
        f"best: score {m['score']:.4f}, harvested {100 * m['success']:.1f} %, "
        f"mean {m['cycle_s']:.2f} simulated s / berry, mean error {m['mean_error_mm']:.2f} mm",
    ]
    if base is not None:
        lines.append(f"starting gains: score {base['score']:.4f}, harvested "
                     f"{100 * base['success']:.1f} %, {base['cycle_s']:.2f} s / berry")  # fmt: skip
    lines.append("Load with: softarm harvest --sim --gains FILE, or "
                 "softarm.Gains(**tomllib.load(f)['gains'])")  # fmt: skip
    return "\n".join(lines)


def _bar_callback(
    tune: Any,
    candidates: int,
    per_candidate: int,
    enabled: bool,
    file: Any = None,
    lines: Any = None,
) -> Any:
    """A Tune callback drawing the search's progress: one tick per trial of a candidate
    (``candidates`` x ``per_candidate`` in all), the candidates finished and the best
    score so far after the bar. Drawn on a terminal only (``file``: default stderr);
    elsewhere (CI, a pipe, nohup) one line per finished candidate goes to ``lines``
    (default stdout), so that a long search is not silent."""
    tqdm = require("tqdm").tqdm

    class Bar(tune.Callback):  # type: ignore[misc]
        def __init__(self) -> None:
            # disable=None: drawn on a terminal only, never into a log file.
            self.bar = tqdm(
                total=candidates * per_candidate, unit=" trial", desc="tune", dynamic_ncols=True,
                file=sys.stderr if file is None else file, disable=None if enabled else True,
                bar_format="{desc}: {n_fmt}/{total_fmt}{unit} |{bar}| {elapsed} elapsed, "
                "ETA {remaining}{postfix}",
            )  # fmt: skip
            self.best = -math.inf
            self.done: dict[str, int] = {}  # trials done, by candidate (Tune's trial id)
            self.reports = 0  # the candidates' reports received
            self.finished = 0  # candidates
            self.drawn = self.started = time.monotonic()

        @property
        def count(self) -> int:
            """Trials done over all candidates (a retried candidate's counted once)."""
            return sum(self.done.values())

        def _set(self, trial: Any, done: int) -> None:
            before = self.count
            self.done[trial.trial_id] = max(
                self.done.get(trial.trial_id, 0), min(done, per_candidate)
            )
            self.bar.update(self.count - before)

        def _finish(self, trial: Any, score: float) -> None:
            self._set(trial, per_candidate)
            self.finished += 1
            self.best = max(self.best, score)
            done = f"{self.finished}/{candidates} candidates, best {self.best:.4f}"
            self.bar.set_postfix_str(done)
            if enabled and self.bar.disable:  # no terminal: a plain line instead
                elapsed = tqdm.format_interval(time.monotonic() - self.started)
                print(f"tune: {done}, {elapsed} elapsed", file=lines or sys.stdout, flush=True)

        def on_trial_result(self, iteration: int, trials: Any, trial: Any, result: Any,
                            **info: Any) -> None:  # fmt: skip
            self.reports += 1
            self._set(trial, int(result.get(TRIALS_DONE, 0)))

        def on_trial_complete(self, iteration: int, trials: Any, trial: Any, **info: Any) -> None:
            self._finish(trial, (trial.last_result or {}).get("score", -math.inf))

        def on_trial_error(self, iteration: int, trials: Any, trial: Any, **info: Any) -> None:
            self._finish(trial, -math.inf)

        def on_step_end(self, iteration: int, trials: Any, **info: Any) -> None:
            # Tune's loop turns many times a second: redraw once a second so that the
            # elapsed time moves while the trials run.
            if time.monotonic() - self.drawn >= 1.0:
                self.drawn = time.monotonic()
                self.bar.refresh()

        def on_experiment_end(self, trials: Any, **info: Any) -> None:
            self.bar.close()

    return Bar()
