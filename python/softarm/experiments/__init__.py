"""The benchtop experiments of the redundancy paper (section IV), reproduced on the
simulated arm (:mod:`softarm.sim`). Each experiment module has
``run(out, seed=0, quick=False, gains=None) -> summary`` and writes CSV, JSON and PNG
files into ``out``; :func:`softarm.experiments.report.write_report` turns the summaries
into ``docs/experiments.md``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from softarm.experiments import hybrid, orientation, position, schedule

#: Experiment name -> its run function.
EXPERIMENTS: dict[str, Callable[..., dict[str, Any]]] = {
    "position": position.run,
    "orientation": orientation.run,
    "hybrid": hybrid.run,
    "schedule": schedule.run,
}


def run(name: str, out: Path, seed: int = 0, quick: bool = False) -> dict[str, Any]:
    """Runs one experiment by name (``"all"`` runs every one; returns {name: summary})."""
    if name == "all":
        return {k: f(out, seed=seed, quick=quick) for k, f in EXPERIMENTS.items()}
    if name not in EXPERIMENTS:
        from softarm.errors import ParameterError

        raise ParameterError(
            f"name = {name!r}: unknown experiment; expected one of {sorted(EXPERIMENTS)} or 'all'"
        )
    return {name: EXPERIMENTS[name](out, seed=seed, quick=quick)}


__all__ = ["EXPERIMENTS", "run"]
