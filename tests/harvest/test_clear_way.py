"""The way a lagging arm takes to each command: straight lines in actuator space
(``straight_step``), the model's gaps along them (``Clearance.gaps_along``,
``ResolverController.way_gaps``) and the check that holds a plan's command whose way
from where the arm is would cross a cane (``Transport.clear_way``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from softarm import Resolver, SoftArm
from softarm.harvest import HarvestConfig, HarvestLog
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.controller import ResolverController
from softarm.harvest.machine.stages.servo import Servo
from softarm.harvest.machine.stages.transport import WAY_SLACK, straight_step
from softarm.sim.bush import Bush

from .fakes import FakeClock, FakeController


def test_straight_step_moves_along_the_line_at_the_fastest_channels_rate() -> None:
    rng = np.random.default_rng(3)
    q0, goal = rng.uniform(0.0, 0.03, 9), rng.uniform(0.0, 0.03, 9)
    step = 0.045 * 0.05
    q, moves = q0.copy(), 0
    while np.any(q != goal):
        move = straight_step(q, goal, step)
        assert np.max(np.abs(move)) <= step + 1e-15
        q = q + move
        moves += 1
        # On the line from q0 to goal: no component across it.
        d, r = goal - q0, q - q0
        assert np.linalg.norm(r - (r @ d) / (d @ d) * d) < 1e-12
        assert moves < 100
    # As many periods as the channel with the most to go needs, no more.
    assert moves == int(np.ceil(np.max(np.abs(goal - q0)) / step - 1e-9))


def test_straight_step_at_the_goal_is_zero() -> None:
    q = np.full(9, 0.01)
    assert np.all(straight_step(q, q, 0.002) == 0.0)


def _model_clearance() -> tuple[SoftArm, Clearance]:
    arm = SoftArm.blackberry()
    bush = Bush.generate(arm, 3, 7)
    return arm, Clearance(arm, [b.curve() for b in bush.branches], 0.03)


def test_gaps_along_a_line_include_both_ends_and_give_the_path_gap() -> None:
    arm, clearance = _model_clearance()
    q0 = np.full(arm.n_actuators, 0.0167)
    q1 = q0 + np.linspace(-0.01, 0.012, arm.n_actuators)
    gaps = clearance.gaps_along(q0, q1, 7)
    assert gaps.shape == (7,)
    assert gaps[0] == pytest.approx(clearance.gap(q0))
    assert gaps[-1] == pytest.approx(clearance.gap(q1))
    assert gaps[3] == pytest.approx(clearance.gap(0.5 * (q0 + q1)))
    assert clearance.path_gap(q0, q1, 7) == pytest.approx(gaps.min())


def test_the_controller_gives_the_models_gaps_only_with_known_canes() -> None:
    arm, clearance = _model_clearance()
    q0 = np.full(arm.n_actuators, 0.0167)
    q1 = q0 + 0.005
    bare = ResolverController(Resolver(arm, mode="hybrid"), ())
    assert bare.way_gaps(q0, q1) is None
    ctl = ResolverController(Resolver(arm, mode="hybrid"), (), clearance=clearance)
    np.testing.assert_allclose(ctl.way_gaps(q0, q1, 5), clearance.gaps_along(q0, q1, 5))


# -- the check, on a one-dimensional "cane": the gap is |q[0] - 0.5| ---------------------


@dataclass
class _Lagging:
    """An actuator whose lag model has ``flight`` still to come towards the last q."""

    flight: np.ndarray | None

    def in_flight(self) -> np.ndarray | None:
        return self.flight


class _CaneAtHalf(FakeController):
    """A controller with the model's gaps of an arm whose only cane is at q[0] = 0.5."""

    def way_gaps(self, q0: np.ndarray, q1: np.ndarray, steps: int = 41) -> np.ndarray:
        t = np.linspace(0.0, 1.0, steps)[:, None]
        return np.abs((q0 + t * (q1 - q0))[:, 0] - 0.5)


def _servo(controller: object, flight: np.ndarray | None) -> Servo:
    return Servo(FakeClock(), controller, _Lagging(flight), HarvestConfig(), HarvestLog())  # type: ignore[arg-type]


def test_a_command_whose_way_from_the_lagging_arm_crosses_a_cane_is_not_taken() -> None:
    q = np.array([0.45, 0.0])  # the last command: 5 cm short of the cane
    servo = _servo(_CaneAtHalf(), flight=np.array([0.25, 0.0]))  # the arm is at 0.2
    across, short = np.array([0.8, 0.0]), np.array([0.3, 0.0])
    # Both commands are clear of the cane on their own; the way to the first is not.
    assert servo.transport.clear_way(q, (across, short)) is short
    # None is clear: the last command is held, and the arm goes on along its way.
    assert servo.transport.clear_way(q, (across,)) is q


def test_without_a_lag_model_the_way_starts_at_the_last_command() -> None:
    q = np.array([0.6, 0.0])  # past the cane already
    servo = _servo(_CaneAtHalf(), flight=None)
    onwards = np.array([0.9, 0.0])
    assert servo.transport.clear_way(q, (onwards,)) is onwards


def test_inside_the_margin_the_way_may_close_in_on_a_cane_only_by_the_slack() -> None:
    margin = HarvestConfig().transport_margin
    q = np.array([0.5 + 0.5 * margin, 0.0])  # the arm there (nothing in flight)
    servo = _servo(_CaneAtHalf(), flight=np.zeros(2))
    away = np.array([0.5 + 2 * margin, 0.0])
    nearer_by_half_the_slack = q - np.array([0.5 * WAY_SLACK, 0.0])
    nearer_by_twice_the_slack = q - np.array([2 * WAY_SLACK, 0.0])
    assert servo.transport.clear_way(q, (away,)) is away
    assert servo.transport.clear_way(q, (nearer_by_half_the_slack,)) is nearer_by_half_the_slack
    assert servo.transport.clear_way(q, (nearer_by_twice_the_slack,)) is q


def test_a_whole_way_is_clear_only_if_every_periods_step_of_it_is() -> None:
    q = np.array([0.45, 0.0])
    servo = _servo(_CaneAtHalf(), flight=np.array([0.25, 0.0]))  # the arm is at 0.2
    assert servo.transport.way_clear(q, np.array([0.3, 0.0]))
    # Its ends are both clear of the cane, the way between them is not.
    assert not servo.transport.way_clear(q, np.array([0.8, 0.0]))
    assert _servo(FakeController(), flight=None).transport.way_clear(q, np.array([0.8, 0.0]))


def test_a_controller_without_known_canes_takes_the_first_command() -> None:
    q = np.array([0.45, 0.0])
    first = np.array([0.8, 0.0])
    servo = _servo(FakeController(), flight=np.array([0.25, 0.0]))  # its way_gaps: None
    assert servo.transport.clear_way(q, (first, q)) is first


def test_the_transport_margin_is_checked() -> None:
    from softarm.errors import ParameterError

    with pytest.raises(ParameterError, match="transport_margin"):
        HarvestConfig(transport_margin=-0.01)
    with pytest.raises(ParameterError, match="transport_margin"):
        HarvestConfig(transport_margin=float("nan"))
