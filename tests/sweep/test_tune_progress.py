"""`softarm tune`'s progress bar counts trials (one (plant point, seed) harvest of a
candidate), not candidates, so it moves and shows an ETA while the first candidate runs."""

from __future__ import annotations

import io
import time
from types import SimpleNamespace

import pytest

from softarm.sweep.tune import TRIALS_DONE, _bar_callback

tune = pytest.importorskip("ray.tune")
pytest.importorskip("tqdm")


class Terminal(io.StringIO):
    """A file tqdm draws on (it draws only on a terminal)."""

    def isatty(self) -> bool:
        return True


def test_the_bar_shows_an_eta_after_the_first_trial_of_the_first_candidate() -> None:
    bar = _bar_callback(tune, candidates=24, per_candidate=4, enabled=True, file=Terminal())
    assert not bar.bar.disable
    assert "0/96 trial" in str(bar.bar) and "ETA ?" in str(bar.bar)
    time.sleep(0.05)
    first = SimpleNamespace(trial_id="a", last_result=None)
    bar.on_trial_result(1, [], first, {"score": 0.1, TRIALS_DONE: 1})
    shown = str(bar.bar)
    assert "1/96 trial" in shown and "ETA ?" not in shown, shown


def test_a_retried_candidate_counts_once_and_a_finished_one_in_full() -> None:
    bar = _bar_callback(tune, candidates=2, per_candidate=3, enabled=True, file=Terminal())
    a = SimpleNamespace(trial_id="a", last_result={"score": 0.75})
    b = SimpleNamespace(trial_id="b", last_result=None)
    bar.on_trial_result(1, [], a, {TRIALS_DONE: 2})
    bar.on_trial_result(1, [], a, {TRIALS_DONE: 1})  # a retry starts again
    bar.on_trial_result(1, [], b, {TRIALS_DONE: 1})
    assert bar.count == bar.bar.n == 3 and bar.reports == 3
    bar.on_trial_complete(2, [], a)
    assert bar.count == bar.bar.n == 4
    assert "1/2 candidates, best 0.7500" in str(bar.bar)
    bar.on_trial_error(3, [], b)  # a failed candidate's trials are done too
    assert bar.count == bar.bar.n == 6
    bar.on_experiment_end([])


def test_a_disabled_bar_still_counts() -> None:
    bar = _bar_callback(tune, candidates=1, per_candidate=2, enabled=False)
    bar.on_trial_result(1, [], SimpleNamespace(trial_id="a"), {TRIALS_DONE: 1})
    assert bar.bar.disable and bar.count == 1
