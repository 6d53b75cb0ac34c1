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
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softarm.errors import ConfigError
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
    and write the best as a ``[gains]`` file at ``out``."""
    ray = require("ray")
    tune = require("ray.tune")
    optuna_search = require("ray.tune.search.optuna")
    from ray.tune.search import ConcurrencyLimiter

    space = spec.tune.space or DEFAULT_SPACE
    n_samples = samples if samples is not None else spec.tune.samples
    if n_samples < 1:
        raise ConfigError(f"--samples: must be >= 1, got {n_samples}")
    base = gains_from(spec.gains).as_dict()
    start_point = {k: base[k] for k in space}
    points = [start_point] if all(_inside(start_point[k], r) for k, r in space.items()) else []
    trials_of = spec.trials()
    expected = sum(t.berries for t in trials_of)
    work = trial_fn or run_trial_rows

    def objective(config: dict[str, Any]) -> None:
        # One candidate: every plant point and seed, in this worker, one after another.
        rows: list[dict[str, Any]] = []
        for t in spec.with_gains(config).trials():
            rows += work(t)
        tune.report(score_rows(rows, expected))

    # Tune's own console tables and Optuna's per-trial log lines: the bar says enough.
    os.environ.setdefault("RAY_AIR_NEW_OUTPUT", "0")
    # Ctrl-C stops the search: Ray Tune's own SIGINT handler would instead end it quietly
    # and return the candidates so far (a gains file from a cut search, or exit 2 with
    # none); KeyboardInterrupt reaches the command line, which exits 130, no gains written.
    os.environ.setdefault("TUNE_DISABLE_SIGINT_HANDLER", "1")
    require("optuna").logging.set_verbosity(require("optuna").logging.WARNING)
    started = init_ray(address, cpus)
    storage = Path(tempfile.mkdtemp(prefix="softarm-tune-"))
    try:
        concurrency = max(1, int(ray.cluster_resources().get("CPU", 1)))
        searcher = optuna_search.OptunaSearch(
            metric="score", mode="max", seed=spec.tune.seed, points_to_evaluate=points or None
        )
        tuner = tune.Tuner(
            tune.with_resources(objective, {"cpu": 1}),
            param_space={k: _domain(tune, r) for k, r in space.items()},
            tune_config=tune.TuneConfig(
                search_alg=ConcurrencyLimiter(searcher, max_concurrent=concurrency),
                metric="score",
                mode="max",
                num_samples=n_samples,
            ),
            run_config=tune.RunConfig(
                name="softarm-tune",
                storage_path=str(storage),
                verbose=0,
                callbacks=[_bar_callback(tune, n_samples, progress)],
                failure_config=tune.FailureConfig(max_failures=1),
            ),
        )
        grid = tuner.fit()
        candidates = []
        for res in grid:
            if res.error is None and res.metrics and "score" in res.metrics:
                candidates.append({**res.config, **{k: res.metrics[k] for k in
                                   ("score", "success", "cycle_s", "mean_error_mm")}})  # fmt: skip
        if not candidates:
            errors = [str(res.error).splitlines()[0] for res in grid if res.error is not None]
            raise ConfigError(
                f"tune: no candidate finished ({errors[0] if errors else 'none ran'})"
            )
    finally:
        shutil.rmtree(storage, ignore_errors=True)
        if started:
            ray.shutdown()
    candidates.sort(key=lambda c: c["score"], reverse=True)
    best = candidates[0]
    gains = {**spec.gains, **{k: best[k] for k in space}}
    metrics = {k: best[k] for k in ("score", "success", "cycle_s", "mean_error_mm")}
    baseline = next((c for c in candidates if all(c[k] == start_point[k] for k in space)), None)
    header = _header(spec, n_samples, metrics, baseline)
    write_gains(out, gains_from(gains), header)
    return TuneOutcome(gains, metrics, baseline, candidates)


def _header(spec: SweepSpec, samples: int, m: dict[str, float], base: dict[str, Any] | None) -> str:
    lines = [
        f"softarm tune {spec.source}: {samples} candidates, Optuna TPE (seed {spec.tune.seed})",
        f"plants: {dict(spec.plant) or 'default'}; seeds {list(spec.seeds)}; "
        f"{spec.berries} berries per bush",
        f"best: score {m['score']:.4f}, harvested {100 * m['success']:.1f} %, "
        f"mean {m['cycle_s']:.2f} simulated s / berry, mean error {m['mean_error_mm']:.2f} mm",
    ]
    if base is not None:
        lines.append(f"starting gains: score {base['score']:.4f}, harvested "
                     f"{100 * base['success']:.1f} %, {base['cycle_s']:.2f} s / berry")  # fmt: skip
    lines.append("Load with: softarm harvest --sim --gains FILE, or "
                 "softarm.Gains(**tomllib.load(f)['gains'])")  # fmt: skip
    return "\n".join(lines)


def _bar_callback(tune: Any, total: int, enabled: bool) -> Any:
    tqdm = require("tqdm").tqdm

    class Bar(tune.Callback):  # type: ignore[misc]
        """One tick per finished candidate, best score so far as the postfix."""

        def __init__(self) -> None:
            # disable=None: drawn on a terminal only, never into a log file.
            self.bar = tqdm(total=total, unit="candidate", desc="tune", file=sys.stderr,
                            disable=None if enabled else True, dynamic_ncols=True)  # fmt: skip
            self.best = -math.inf

        def on_trial_complete(self, iteration: int, trials: Any, trial: Any, **info: Any) -> None:
            score = (trial.last_result or {}).get("score", -math.inf)
            self.best = max(self.best, score)
            self.bar.update(1)
            self.bar.set_postfix(best=f"{self.best:.4f}")

        def on_trial_error(self, iteration: int, trials: Any, trial: Any, **info: Any) -> None:
            self.bar.update(1)

        def on_experiment_end(self, trials: Any, **info: Any) -> None:
            self.bar.close()

    return Bar()
