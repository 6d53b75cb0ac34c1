"""``softarm.sweep.run``: a sweep in this process, one trial after another, without Ray
(no ``sweep`` extra needed): the rows ``softarm sweep`` streams to results.parquet."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from softarm.sweep.spec import SweepSpec, TrialSpec, load_spec, parse_spec

__all__ = ["run"]


def run(
    spec: SweepSpec | str | Path | Mapping[str, Any],
    *,
    gains: Mapping[str, Any] | None = None,
    on_trial: Callable[[TrialSpec, list[dict[str, Any]]], None] | None = None,
) -> list[dict[str, Any]]:
    """Harvest every (plant point, seed) of ``spec`` in this process, one trial after
    another, and return one row per berry (the columns of ``softarm sweep``'s
    results.parquet: ``trial_id``, ``seed``, the swept plant keys, then
    :data:`softarm.sweep.trial.BERRY_COLUMNS`). Needs no Ray, pyarrow or tqdm.

    Args:
        spec: a :class:`SweepSpec`, a spec file (TOML, as ``softarm sweep SPEC``) or its
            parsed document (``{"sweep": {"seeds": [0], "berries": 1, "plant": {...}}}``).
        gains: resolver gain keywords over the spec's own (``--gains``).
        on_trial: called as ``on_trial(trial, rows)`` after each trial.

    A trial that raises is one row with ``error`` set, and the sweep goes on, as on Ray.
    For many trials, ``softarm sweep`` spreads them over every core (or a cluster).
    """
    from softarm.sweep.trial import run_trial_rows

    if isinstance(spec, (str, Path)):
        spec = load_spec(spec)
    elif not isinstance(spec, SweepSpec):
        spec = parse_spec(spec)
    if gains:
        spec = spec.with_gains(gains)
    rows: list[dict[str, Any]] = []
    for trial in spec.trials():
        got = run_trial_rows(trial, single_threaded=False)
        rows += got
        if on_trial is not None:
            on_trial(trial, got)
    return rows
