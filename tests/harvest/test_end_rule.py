"""Fine positioning's "confidence" end rule (:func:`~softarm.harvest.machine.stages.end_rules.
confidently_within`, its offsets kept by :class:`~softarm.harvest.machine.stages.goal.Progress`):
a noisy measurement of an arm on the berry ends within a window of steps where three
values in a row under the tolerance do not come; a biased measurement never ends where
the values alone do; frames read again are no new measurement; ``fine_end_rule = "steps"``
keeps the rule before."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from softarm.harvest.machine.interfaces import BerryFix, FloatArray, Observation
from softarm.harvest.machine.outcome import Ending
from softarm.harvest.machine.stages.end_rules import confidently_within, settled_or_out_of_time
from softarm.harvest.machine.stages.goal import Aim, Progress, ServoGoal
from softarm.harvest.machine.states import HarvestState
from softarm.harvest_config import HarvestConfig

TOL = 0.0005  # fine_tolerance
WINDOW = 20
FEWEST = 3
CONFIDENCE = 0.95


def _offsets(true_mm: float, sigma_mm: float, seed: int, n: int = 200) -> list[FloatArray]:
    """``n`` measured offsets (m) of an arm ``true_mm`` off the goal along x, each with
    independent noise of ``sigma_mm`` per axis."""
    rng = np.random.default_rng(seed)
    noise = rng.normal(0.0, sigma_mm * 1e-3, (n, 3))
    return [np.array([true_mm * 1e-3, 0.0, 0.0]) + e for e in noise]


def _confident_after(offsets: list[FloatArray]) -> int | None:
    """How many offsets the rule takes to end (None: it does not)."""
    progress = Progress(0.0)
    for k, offset in enumerate(offsets, start=1):
        if progress.measured(offset, WINDOW) and confidently_within(
            progress.offsets, TOL, FEWEST, CONFIDENCE
        ):
            return k
    return None


def _in_a_row_after(offsets: list[FloatArray], steps: int = FEWEST) -> int | None:
    """How many offsets the rule before (``steps`` values in a row within TOL) takes."""
    run = 0
    for k, offset in enumerate(offsets, start=1):
        run = run + 1 if np.linalg.norm(offset) <= TOL else 0
        if run >= steps:
            return k
    return None


def test_noisy_on_target_ends_within_a_window() -> None:
    # 0.1 mm off with 0.3 mm of noise per axis: single values are around 0.5 mm, so
    # three in a row under it take 43 steps here; their mean is on the berry.
    offsets = _offsets(0.1, 0.3, seed=8)
    assert (_in_a_row_after(offsets) or np.inf) > WINDOW
    ended = _confident_after(offsets)
    assert ended is not None and ended <= WINDOW


def test_biased_measurement_does_not_end() -> None:
    # 0.6 mm off with 0.25 mm of noise: three values in a row under 0.5 mm come by
    # chance (after 6 steps here); the estimate stays off the goal for 200 steps.
    offsets = _offsets(0.6, 0.25, seed=0)
    assert _in_a_row_after(offsets) is not None
    assert _confident_after(offsets) is None


def test_noiseless_converging_arm_ends_no_later_than_three_in_a_row() -> None:
    # The tag world: the error shrinks by a third a step under little noise; the mean
    # of the last offsets lags, the line through them does not.
    rng = np.random.default_rng(3)
    direction = np.array([0.6, 0.0, 0.8])
    offsets = [direction * 0.05 * 0.65**k + rng.normal(0, 1e-5, 3) for k in range(60)]
    before, ended = _in_a_row_after(offsets), _confident_after(offsets)
    assert before is not None and ended is not None and ended <= before


def test_frames_read_again_are_no_new_measurement() -> None:
    # One reading of 0.45 mm, its frames read again: without the check the offsets would
    # have no spread and the bound would be 0.45 mm, within the tolerance.
    progress = Progress(0.0)
    offset = np.array([0.00045, 0.0, 0.0])
    assert progress.measured(offset, WINDOW)
    assert not any(progress.measured(offset.copy(), WINDOW) for _ in range(10))
    assert len(progress.offsets) == 1
    assert confidently_within([offset] * FEWEST, TOL, FEWEST, CONFIDENCE) is not None


def test_the_window_keeps_the_last_offsets() -> None:
    progress = Progress(0.0)
    for k in range(5):
        progress.measured(np.full(3, float(k)), 3)
    assert [o[0] for o in progress.offsets] == [2.0, 3.0, 4.0]


class _Log:
    def __init__(self) -> None:
        self.events: list[tuple[str, dict[str, Any]]] = []

    def event(self, kind: str, **fields: Any) -> None:
        self.events.append((kind, fields))


class _Watch:
    def log_step(self, *args: object) -> None:
        pass


def _fine(rule: str, offsets: list[FloatArray]) -> tuple[int | None, _Log]:
    """Feed ``offsets`` as the measured grasp-point offsets of fine positioning through
    :func:`settled_or_out_of_time` under ``rule``: the step it SETTLED at (or None)."""
    cfg = HarvestConfig(fine_end_rule=rule)
    log = _Log()
    link = cast(Any, SimpleNamespace(cfg=cfg, log=log))
    goal = ServoGoal(cfg.grasp_offset, cfg.fine_tolerance, cfg.fine_timeout, cfg.fine_budget)
    progress, axis, q = Progress(0.0), np.array([0.0, 1.0, 0.0]), np.zeros(9)
    fix = BerryFix(np.zeros(3), "eye_in_hand")
    for k, offset in enumerate(offsets, start=1):
        pose = np.eye(4)
        pose[:3, 3] = offset  # the goal at the origin: the pose's offset is the grasp's
        seen = Observation(0.05 * k, pose, fix)
        aim = Aim(np.eye(4), float(np.linalg.norm(offset)), 0.0)
        ended = settled_or_out_of_time(
            link, cast(Any, _Watch()), HarvestState.FINE_POSITIONING, seen, q, axis, aim,
            goal, progress,
        )  # fmt: skip
        if ended is not None:
            assert ended.ending is Ending.SETTLED
            return k, log
    return None, log


@pytest.mark.parametrize("rule", ["confidence", "steps"])
def test_the_setting_chooses_the_rule(rule: str) -> None:
    offsets = _offsets(0.1, 0.3, seed=8, n=WINDOW)
    ended, log = _fine(rule, offsets)
    if rule == "confidence":
        assert ended == _confident_after(offsets)
        (kind, fields), *_ = log.events
        assert kind == "fine_confident" and fields["bound"] <= TOL
    else:  # three in a row, as before: not within these steps
        assert ended is None and _in_a_row_after(offsets) is None and not log.events
