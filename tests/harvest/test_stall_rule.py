"""The harvest's stall rule (:class:`~softarm.harvest.machine.stages.goal.Progress`): a stage
stalls only when the resolver has been saturated *and* the error has made no progress,
each for longer than ``stall_time``; a saturation that began at t = 0.0 counts from 0.0."""

from __future__ import annotations

from softarm.harvest.machine.stages.goal import Progress

STALL_TIME = 1.0
STALL_PROGRESS = 1e-3


def _progress(steps: list[tuple[float, float, bool]], start: float = 0.0) -> Progress:
    """A Progress after ``steps`` of (t, error, saturated)."""
    progress = Progress(start)
    for t, error, saturated in steps:
        progress.update(t, error, saturated, STALL_PROGRESS)
    return progress


def test_saturated_but_still_progressing_is_not_a_stall() -> None:
    # Saturated since 0.1 (2.4 s by t = 2.5), but the error kept falling until 2.0: the
    # last progress is 0.5 s old, so not stalled (a rule on saturation alone, or on
    # either condition, would say stalled).
    steps = [(0.1 * k, 0.05 - 0.002 * k, True) for k in range(1, 21)]
    progress = _progress([*steps, (2.5, 0.05 - 0.002 * 20, True)])
    assert progress.saturated_since == 0.1 and progress.best_t == 2.0
    assert not progress.stalled(2.5, STALL_TIME)
    assert progress.stalled(3.01, STALL_TIME)  # both past 1 s now


def test_no_progress_but_not_saturated_long_is_not_a_stall() -> None:
    # No progress since 0.0, saturated only since 2.0: not stalled at 2.5, stalled
    # after 3.0.
    steps = [(0.0, 0.05, False), (1.0, 0.05, False), (2.0, 0.05, True), (2.5, 0.05, True)]
    progress = _progress(steps)
    assert progress.best_t == 0.0 and progress.saturated_since == 2.0
    assert not progress.stalled(2.5, STALL_TIME)
    assert progress.stalled(3.01, STALL_TIME)


def test_a_step_off_the_limit_restarts_the_saturation_clock() -> None:
    progress = _progress([(0.0, 0.05, True), (1.0, 0.05, False), (1.5, 0.05, True)])
    assert progress.saturated_since == 1.5
    assert not progress.stalled(2.0, STALL_TIME)


def test_a_saturation_that_began_at_time_zero_counts_from_zero() -> None:
    # 0.0 is a time like any other, not "unset": saturated from 0.0 without progress,
    # the stage is stalled past 1 s.
    progress = _progress([(0.0, 0.05, True), (0.5, 0.05, True), (1.2, 0.05, True)])
    assert progress.saturated_since == 0.0
    assert progress.stalled(1.2, STALL_TIME)


def test_progress_smaller_than_stall_progress_is_no_progress() -> None:
    progress = _progress([(0.0, 0.05, True), (0.5, 0.05 - STALL_PROGRESS / 2, True)])
    assert progress.best_t == 0.0 and progress.best == 0.05
    progress.update(0.6, 0.05 - 2 * STALL_PROGRESS, True, STALL_PROGRESS)
    assert progress.best_t == 0.6
