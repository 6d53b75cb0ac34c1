"""Fake trial functions for the Ray tests: rows of the right shape without a harvest, so
that the failure, resume and cluster tests take seconds. Sent to the workers by value."""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path
from typing import Any

from softarm.sweep.spec import TrialSpec
from softarm.sweep.trial import BERRY_COLUMNS


def rows(trial: TrialSpec, harvested: bool = True) -> list[dict[str, Any]]:
    """One row per berry, every berry harvested in 2 s (+ the seed) of simulated time."""
    out = []
    for i in range(trial.berries):
        row: dict[str, Any] = dict.fromkeys(BERRY_COLUMNS)
        row.update(trial_id=trial.trial_id, seed=trial.seed, **trial.plant)
        row.update(berry=i, tag_id=10 + i, harvested=harvested, duration_s=2.0 + trial.seed,
                   true_position_error_mm=0.5, branch_contact_steps=0, min_branch_gap_m=0.03,
                   sim_s=(2.0 + trial.seed) * trial.berries, node=str(os.getpid()))  # fmt: skip
        out.append(row)
    return out


def quick(trial: TrialSpec) -> list[dict[str, Any]]:
    return rows(trial)


def crash_on_seed_1(trial: TrialSpec) -> list[dict[str, Any]]:
    """The worker process dies (as if killed, or out of memory) on seed 1, every time."""
    if trial.seed == 1:
        os._exit(1)
    return rows(trial)


def slow(trial: TrialSpec) -> list[dict[str, Any]]:
    time.sleep(2.0)
    return rows(trial)


def crash_marker(trial: TrialSpec) -> Path:
    return Path(tempfile.gettempdir()) / f"softarm-sweep-test-crashed-{trial.trial_id}"


def crash_once(trial: TrialSpec) -> list[dict[str, Any]]:
    """The worker dies on the first attempt at each trial; Ray's retry then succeeds."""
    marker = crash_marker(trial)
    if not marker.exists():
        marker.touch()
        os._exit(1)
    return rows(trial)
