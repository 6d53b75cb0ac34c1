"""Move shaping: the lead through the regulators' first-order lag (``lead_cap``), inside
the safety layer's limits; a plan's feedforward through periods without a cube pose
(``follow_blind_time``); the hand-over of a plan's last leg (``handover_tolerance``)."""

from __future__ import annotations

import numpy as np
import pytest

from softarm._core import lead_gain
from softarm.errors import ParameterError
from softarm.hardware import SafePressureBank, SimulatedPressureBank
from softarm.hardware.pressure_map import METRES_PER_PSI
from softarm.harvest import BerryTarget, HarvestConfig, HarvestLog, SafeActuator
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.outcome import Fault
from softarm.harvest.machine.stages.servo import Servo
from softarm.harvest.machine.stages.transport import straight_step
from softarm.harvest.machine.states import FaultReason, HarvestState

from .fakes import (
    BERRIES,
    FakeClock,
    FakeController,
    FakeLocator,
    FakePlant,
    FakeTracker,
    FakeVision,
)

PERIOD = 0.05
MAX_RATE = 100.0  # psi/s, the safety layer's default
TAU = 0.8  # s, the slow plant's regulators


class LaggingPlant(FakePlant):
    """Pressures follow the command through a first-order lag ``tau`` (s), one step of
    ``PERIOD`` at each tick of the clock (``advance``)."""

    def __init__(self, tau: float) -> None:
        super().__init__()
        self.command = np.zeros(3)
        self.a = float(np.exp(-PERIOD / tau))

    def command_pressures(self, psi: np.ndarray) -> None:
        self.command = np.array(psi, dtype=np.float64)

    def advance(self, _t: float) -> None:
        self.psi = self.a * self.psi + (1.0 - self.a) * self.command


def _lagging_rig(lead: float) -> tuple[FakeClock, LaggingPlant, SafePressureBank, SafeActuator]:
    clock = FakeClock()
    plant = LaggingPlant(TAU)
    clock.hooks.append(plant.advance)
    bank = SafePressureBank(
        SimulatedPressureBank(plant, channels=3), 70.0, MAX_RATE, 0.5, clock.now,
        watchdog_thread=False,
    )  # fmt: skip
    actuator = SafeActuator(bank, lag=(TAU, PERIOD), now=clock.now, lead=lead)
    return clock, plant, bank, actuator


def _ramp_and_hold(lead: float, goal_psi: np.ndarray) -> tuple[float, list[np.ndarray]]:
    """Ramp the command to ``goal_psi`` at 0.045 m/s and hold it: the time (s) the plant
    takes to come within 0.5 psi of it, and every pressure the safety layer sent."""
    clock, plant, bank, actuator = _lagging_rig(lead)
    goal = goal_psi * METRES_PER_PSI
    q = np.zeros(3)
    sent = [bank.last_sent.copy()]
    while clock.now() < 20.0:
        q = q + straight_step(q, goal, 0.045 * PERIOD)
        actuator.send(q)
        sent.append(bank.last_sent.copy())
        clock.sleep(PERIOD)
        if np.all(q == goal) and np.max(np.abs(plant.psi - goal_psi)) < 0.5:
            return clock.now(), sent
    raise AssertionError("the plant never arrived")


@pytest.mark.parametrize("goal", [np.array([30.0, 10.0, 0.0]), np.array([60.0, 65.0, 20.0])])
def test_the_lead_brings_a_first_order_lag_to_its_target_sooner(goal: np.ndarray) -> None:
    plain, _ = _ramp_and_hold(0.0, goal)
    led, _ = _ramp_and_hold(lead_gain(TAU, PERIOD, 1.5), goal)
    more, _ = _ramp_and_hold(lead_gain(TAU, PERIOD, 4.0), goal)
    assert led < 0.75 * plain
    assert more < led


@pytest.mark.parametrize("cap", [1.5, 4.0, 20.0])
def test_the_led_commands_keep_inside_the_safety_layers_limits(cap: float) -> None:
    for goal in (np.array([70.0, 35.0, 0.0]), np.array([5.0, 68.0, 40.0])):
        _, sent = _ramp_and_hold(lead_gain(TAU, PERIOD, cap), goal)
        psi = np.array(sent)
        assert np.all(psi >= 0.0) and np.all(psi <= 70.0)
        assert np.max(np.abs(np.diff(psi, axis=0))) <= MAX_RATE * PERIOD + 1e-9


# -- a plan followed while the tracker refuses poses -------------------------------------


def _follow(config: HarvestConfig, blind: object, log: HarvestLog | None = None) -> float:
    """Follow a plan from the vented arm to a waypoint on the instant fake plant with the
    tracker blind while ``blind(t)``; the time (s) the follow took."""
    clock, plant = FakeClock(), FakePlant()
    bank = SafePressureBank(
        SimulatedPressureBank(plant, channels=3), 70.0, MAX_RATE, 0.5, clock.now,
        watchdog_thread=False,
    )  # fmt: skip
    log = HarvestLog() if log is None else log
    servo = Servo(clock, FakeController(), SafeActuator(bank), config, log)
    vision = FakeVision(FakeTracker(plant, blind=blind), FakeLocator(dict(BERRIES)))  # type: ignore[arg-type]
    vision.select(BerryTarget(1))
    watch = BerryWatch(vision, clock, BerryTarget(1), log, config.marker_timeout)
    q_way = np.array([0.02, 0.015, 0.025])
    servo.transport.follow(watch, HarvestState.INITIAL_PLACEMENT, np.zeros(3), q_way, 30.0)
    return clock.now()


def _two_of_three_refused(t: float) -> bool:
    """A fast move's poses: two periods of three refused as jumps."""
    return round(t / PERIOD) % 3 != 0


def test_the_plan_goes_on_through_periods_without_a_pose() -> None:
    waiting = _follow(HarvestConfig(follow_blind_time=0.0), _two_of_three_refused)
    going_on = _follow(HarvestConfig(), _two_of_three_refused)
    seeing = _follow(HarvestConfig(), lambda t: False)
    assert going_on < 0.5 * waiting
    assert going_on <= seeing + 3 * PERIOD


def test_without_a_pose_for_longer_than_the_blind_time_the_arm_waits() -> None:
    config = HarvestConfig(follow_blind_time=0.15, marker_timeout=0.5)
    log = HarvestLog()
    with pytest.raises(Fault) as lost:
        _follow(config, lambda t: t > 0.12, log)
    assert lost.value.reason is FaultReason.MARKER_LOST
    steps = [(r["t"], np.array(r["q"])) for r in log.records if r["kind"] == "step"]
    moving = [
        t for (t, q), (_, q_prev) in zip(steps[1:], steps[:-1], strict=True) if np.any(q != q_prev)
    ]
    # The last pose at t = 0.1: the plan goes on until 0.1 + 0.15 s, then holds.
    assert max(moving) <= 0.1 + 0.15 + 1e-9
    assert max(moving) > 0.1 + PERIOD


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("follow_blind_time", -0.1),
        ("follow_blind_time", float("nan")),
        ("handover_tolerance", 0.0),
        ("lead_cap", -1.0),
        ("lead_cap", 21.0),
        ("lead_cap", float("inf")),
    ],
)
def test_bad_move_shaping_keys_name_themselves(key: str, value: float) -> None:
    with pytest.raises(ParameterError, match=key):
        HarvestConfig(**{key: value})  # type: ignore[arg-type]


# -- the way home passes its waypoints -----------------------------------------------------


def test_the_way_home_passes_a_waypoint_the_arm_is_already_at() -> None:
    """The back-out leaves the arm at the plan's pre-grasp pose but a few mm of elongation
    off the plan's q: the way home goes on from there, not back to that q first."""
    clock, plant = FakeClock(), FakePlant()
    bank = SafePressureBank(
        SimulatedPressureBank(plant, channels=3), 70.0, MAX_RATE, 0.5, clock.now,
        watchdog_thread=False,
    )  # fmt: skip
    log, config = HarvestLog(), HarvestConfig()
    servo = Servo(clock, FakeController(), SafeActuator(bank), config, log)
    vision = FakeVision(FakeTracker(plant), FakeLocator(dict(BERRIES)))
    vision.select(BerryTarget(1))
    watch = BerryWatch(vision, clock, BerryTarget(1), log, config.marker_timeout)
    q_way, home = np.array([0.02, 0.015, 0.025]), np.full(3, 0.0167)
    q = q_way + np.array([0.002, -0.002, 0.001])  # its pose 9 mm from the waypoint's
    servo.transport.ramp(watch, HarvestState.RETURN_HOME, np.zeros(3), q, 10.0)
    q = servo.transport.way_back(watch, HarvestState.RETURN_HOME, q, (q_way, home), clock.now())
    np.testing.assert_array_equal(q, home)
    commanded = [np.array(r["q"]) for r in log.records if r["kind"] == "step"]
    nearest = min(float(np.max(np.abs(c - q_way))) for c in commanded)
    assert nearest > 0.0005  # never sent back to the plan's q on the way


# -- the hand-over of a plan's last leg ----------------------------------------------------


class _OffModel(FakeController):
    """A model 2 cm off the arm along x: the plan's end pose is never measured within
    ``placement_tolerance`` at the plan's q."""

    def model_pose(self, q: np.ndarray) -> np.ndarray:
        pose = super().model_pose(q)
        pose[0, 3] += 0.02
        return pose

    def follow_step(self, q: np.ndarray, target: np.ndarray, current: np.ndarray):  # type: ignore[no-untyped-def]
        return np.asarray(q, dtype=np.float64), False  # no correction: the plan alone


def _hand_over(tolerance: float) -> tuple[float, float]:
    """Follow a plan on the lagging plant to its end; when the follow returned (s) and
    the motion the lag model still had in flight then (m)."""
    clock, plant, _, actuator = _lagging_rig(lead_gain(TAU, PERIOD, 1.5))
    log, config = HarvestLog(), HarvestConfig(handover_tolerance=tolerance)
    servo = Servo(clock, _OffModel(), actuator, config, log)
    vision = FakeVision(FakeTracker(plant), FakeLocator(dict(BERRIES)))
    vision.select(BerryTarget(1))
    watch = BerryWatch(vision, clock, BerryTarget(1), log, config.marker_timeout)
    q_way = np.array([0.02, 0.015, 0.025])
    servo.transport.follow(watch, HarvestState.INITIAL_PLACEMENT, np.zeros(3), q_way, 30.0)
    flight = actuator.in_flight()
    assert flight is not None
    return clock.now(), float(np.max(np.abs(flight)))


def test_a_plans_end_hands_over_once_the_lag_model_has_the_arm_within_the_tolerance() -> None:
    late, late_flight = _hand_over(0.001)
    early, early_flight = _hand_over(0.01)
    assert late_flight <= 0.001 < early_flight <= 0.01
    assert early < late - 0.3


# -- the correction against the plan's point where the arm is -------------------------------


def _commands_following_on_the_lagging_plant() -> tuple[np.ndarray, list[np.ndarray]]:
    """Follow a plan on the lagging plant with an exact model (nothing for the correction
    to take out); the plan's end and every q commanded."""
    clock, plant, _, actuator = _lagging_rig(lead_gain(TAU, PERIOD, 1.5))
    log, config = HarvestLog(), HarvestConfig()
    servo = Servo(clock, FakeController(), actuator, config, log)
    vision = FakeVision(FakeTracker(plant), FakeLocator(dict(BERRIES)))
    vision.select(BerryTarget(1))
    watch = BerryWatch(vision, clock, BerryTarget(1), log, config.marker_timeout)
    q_way = np.array([0.02, 0.015, 0.025])
    servo.transport.follow(watch, HarvestState.INITIAL_PLACEMENT, np.zeros(3), q_way, 30.0)
    return q_way, [np.array(r["q"]) for r in log.records if r["kind"] == "step"]


def test_the_lag_is_not_corrected_as_an_error_while_following_a_plan() -> None:
    """The arm trails the plan by the regulators' lag; measured against the plan's point
    the lag read as an error and the correction piled up along the motion, past the plan's
    end (18 mm of elongation here). Against the plan's point where the arm is, an exact
    model leaves the correction nothing to do: the commands keep within the plan."""
    q_way, commanded = _commands_following_on_the_lagging_plant()
    past_the_end = max(float(np.max(q - q_way)) for q in commanded)
    assert past_the_end <= 1e-4
