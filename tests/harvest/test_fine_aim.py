"""``fine_aim``: fine positioning servoes on to the measured berry before its end rule
may end it (:func:`~softarm.harvest.machine.stages.end_rules.aimed`): an arm converging
from the pre-grasp pose no longer ends on the tolerance's edge; after ``FINE_AIM_S`` the
rule alone ends it; off (0, the default) the rule alone, as before; a bad value is one
typed error naming the key."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.harvest.machine.interfaces import BerryFix, FloatArray, Observation
from softarm.harvest.machine.outcome import Ending
from softarm.harvest.machine.stages.end_rules import FINE_AIM_S, aimed, settled_or_out_of_time
from softarm.harvest.machine.stages.goal import Aim, Progress, ServoGoal
from softarm.harvest.machine.states import HarvestState
from softarm.harvest_config import HarvestConfig

PERIOD = 0.05
AIM = 0.0002  # fine_aim (m)


class _Quiet:
    def event(self, *args: object, **fields: object) -> None:
        pass

    def log_step(self, *args: object) -> None:
        pass


def _closed_loop(
    rule: str, plant: Callable[[FloatArray, FloatArray], FloatArray], aim: float = AIM
) -> FloatArray:
    """Fine positioning's end rule closing a loop: each step the grasp point's measured
    offset from the berry (true offset plus noise) goes through
    :func:`settled_or_out_of_time`, and, unless it ended, ``plant`` moves the true offset
    by a command of the measured offset's opposite. Returns the true offset (m) at the
    end."""
    cfg = HarvestConfig(fine_end_rule=rule, fine_aim=aim)
    link = cast(Any, SimpleNamespace(cfg=cfg, log=_Quiet()))
    goal = ServoGoal(cfg.grasp_offset, cfg.fine_tolerance, cfg.fine_timeout, cfg.fine_budget)
    progress, q = Progress(0.0), np.zeros(9)
    rng = np.random.default_rng(5)
    true = np.array([0.0, 0.0, -0.001])  # 1 mm short along the axis
    fix = BerryFix(np.zeros(3), "eye_in_hand")
    for k in range(1, 400):
        measured = true + rng.normal(0.0, 3e-5, 3)
        pose = np.eye(4)
        pose[:3, 3] = measured  # the goal at the origin: the pose's offset is the grasp's
        seen = Observation(PERIOD * k, pose, fix)
        step = Aim(np.eye(4), float(np.linalg.norm(measured)), 0.0)
        ended = settled_or_out_of_time(
            link, cast(Any, _Quiet()), HarvestState.FINE_POSITIONING, seen, q,
            np.array([0.0, 0.0, 1.0]), step, goal, progress,
        )  # fmt: skip
        if ended is not None:
            assert ended.ending is Ending.SETTLED
            return true
        true = plant(true, -measured)
    raise AssertionError("fine positioning did not end")


def _sluggish(true: FloatArray, command: FloatArray) -> FloatArray:
    """A plant that is not the controller's model: it moves 8 % of each command (the
    model expects the loop's gain of a half)."""
    return true + 0.08 * command


@pytest.mark.parametrize("rule", ["steps", "confidence"])
def test_converging_arm_ends_on_the_berry_not_the_tolerance_edge(rule: str) -> None:
    # Converging from 1 mm, each step 8 % nearer: the rule alone ends three steps
    # after the first offset within 0.5 mm (0.39 mm true); servoed on, within the aim.
    true = _closed_loop(rule, _sluggish)
    assert float(np.linalg.norm(true)) <= AIM + 1e-4


def test_off_by_default_the_rule_alone_ends_on_the_edge() -> None:
    assert HarvestConfig().fine_aim == 0.0
    true = _closed_loop("steps", _sluggish, aim=0.0)
    assert float(np.linalg.norm(true)) > 0.00035


def test_after_the_aim_time_the_rule_alone_ends() -> None:
    # A measured offset that sticks 0.4 mm out (the play holds the arm) ends on the
    # rule once FINE_AIM_S is spent, not at the 12 s budget.
    stuck = [np.array([0.0004, 0.0, 0.0])] * 3
    assert not aimed(stuck, 3, FINE_AIM_S - PERIOD, AIM)
    assert aimed(stuck, 3, FINE_AIM_S, AIM)
    assert aimed(stuck, 3, 0.0, 0.0)  # off
    assert aimed([np.array([0.0001, 0.0001, 0.0])] * 3, 3, 0.0, AIM)
    assert not aimed([np.zeros(3)] * 2, 3, 0.0, AIM)  # too few offsets yet


def test_the_aim_averages_vectors_not_norms() -> None:
    # Noise of 0.15 mm per axis about the berry: each norm is ~0.26 mm, over the aim;
    # the mean of three vectors is within it.
    offsets = [
        np.array(v) * 1e-3 for v in ([0.15, -0.1, 0.1], [-0.15, 0.1, -0.1], [0.0, 0.15, 0.15])
    ]
    assert all(float(np.linalg.norm(o)) > AIM for o in offsets)
    assert aimed(offsets, 3, 0.0, AIM)


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (-1e-4, "fine_aim must be finite and >= 0, got -0.0001"),
        (0.0005, "fine_aim must be in [0, fine_tolerance 0.0005), got 0.0005"),
        (float("nan"), "fine_aim must be a finite number"),
    ],
)
def test_bad_values_name_the_key(value: float, message: str) -> None:
    with pytest.raises(ParameterError) as info:
        HarvestConfig(fine_aim=value)
    assert message in str(info.value)
