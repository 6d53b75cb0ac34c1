"""The moves on a slow plant that is not the controller's model: placement and the
back-out end on where the commands already sent put the arm (the lag model's motion in
flight carried through the model; the back-out only once the arm is within 2 cm), and
the way home does not send the arm back to the plan's pre-grasp q once the back-out has
it at the pre-grasp pose."""

from __future__ import annotations

import numpy as np

from softarm._core import lead_gain
from softarm.hardware import SafePressureBank, SimulatedPressureBank
from softarm.hardware.pressure_map import METRES_PER_PSI
from softarm.harvest import BerryTarget, HarvestConfig, HarvestLog, SafeActuator
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.machine.stages.servo import Servo
from softarm.harvest.machine.states import HarvestState

from .fakes import (
    BERRIES,
    FACING_Y,
    P0,
    FakeClock,
    FakeController,
    FakeLocator,
    FakeTracker,
    FakeVision,
    K,
)

PERIOD = 0.05
TAU = 0.8  # s, the slow plant's regulators
GAIN_ERROR = 1.05  # the plant moves 5 % more per psi than the controller's model


class SlowPlant:
    """Pressures follow the command through a first-order lag ``TAU``; the end effector
    moves ``GAIN_ERROR`` times what the controller's model says."""

    def __init__(self) -> None:
        self.psi = np.zeros(3)
        self.command = np.zeros(3)
        self.a = float(np.exp(-PERIOD / TAU))

    def command_pressures(self, psi: np.ndarray) -> None:
        self.command = np.array(psi, dtype=np.float64)

    def pressures(self) -> np.ndarray:
        return self.psi.copy()

    def advance(self, _t: float) -> None:
        self.psi = self.a * self.psi + (1.0 - self.a) * self.command

    def pose(self) -> np.ndarray:
        out = np.eye(4)
        out[:3, :3] = FACING_Y
        out[:3, 3] = P0 + GAIN_ERROR * K * self.psi * METRES_PER_PSI
        return out


class PredictingController(FakeController):
    """The fake's proportional step closed on the measured pose plus the model's motion
    still in flight (a Smith predictor, as the harvest's resolver closes its loop)."""

    def __init__(self, actuator: SafeActuator) -> None:
        super().__init__(gain=0.5)
        self.actuator = actuator

    def step(self, q: np.ndarray, target: np.ndarray, current: np.ndarray | None):  # type: ignore[no-untyped-def]
        assert current is not None
        flight = self.actuator.in_flight()
        ahead = current.copy()
        ahead[:3, 3] += K * (np.zeros(3) if flight is None else flight)
        return super().step(q, target, ahead)


class OffModel(PredictingController):
    """A model whose poses are 2 cm off the arm's along x (a sagging rod): the plan's
    pre-grasp q is never measured within ``placement_tolerance`` of its model pose."""

    def model_pose(self, q: np.ndarray) -> np.ndarray:
        pose = super().model_pose(q)
        pose[0, 3] += 0.02
        return pose


def slow_actuator() -> tuple[FakeClock, SlowPlant, SafeActuator]:
    """A clock, the slow plant it advances, and the safety layer's actuator on it with
    the plant's lag model and the regulators' lead, as the harvest's stack builds it."""
    clock, plant = FakeClock(), SlowPlant()
    clock.hooks.append(plant.advance)
    bank = SafePressureBank(
        SimulatedPressureBank(plant, channels=3), 70.0, 100.0, 0.5, clock.now,
        watchdog_thread=False,
    )  # fmt: skip
    actuator = SafeActuator(
        bank, lag=(TAU, PERIOD), now=clock.now, lead=lead_gain(TAU, PERIOD, 1.5)
    )
    return clock, plant, actuator


def _slow_rig(
    off: bool = False,
) -> tuple[FakeClock, SlowPlant, SafeActuator, Servo, BerryWatch, HarvestLog]:
    clock, plant, actuator = slow_actuator()
    log, config = HarvestLog(), HarvestConfig()
    controller = (OffModel if off else PredictingController)(actuator)
    servo = Servo(clock, controller, actuator, config, log)
    vision = FakeVision(FakeTracker(plant), FakeLocator(dict(BERRIES)))  # type: ignore[arg-type]
    vision.select(BerryTarget(1))
    watch = BerryWatch(vision, clock, BerryTarget(1), log, config.marker_timeout)
    return clock, plant, actuator, servo, watch, log


def _pre_grasp_error(plant: SlowPlant, config: HarvestConfig) -> float:
    """The true end effector's distance (m) from the pre-grasp pose of berry 1."""
    goal = BERRIES[1] - (config.standoff + config.grasp_offset) * np.array([0.0, 1.0, 0.0])
    return float(np.linalg.norm(plant.pose()[:3, 3] - goal))


def test_placement_ends_on_where_the_commands_sent_put_the_slow_arm() -> None:
    """Placement hands over once the commands sent put the arm within the tolerance,
    while the arm, a regulator's lag behind them, is still farther out (before: only
    once the arm itself was measured there); held, those commands bring it there."""
    clock, plant, _, servo, watch, _ = _slow_rig()
    config = servo.link.cfg
    q = np.zeros(3)
    out = servo.place(watch, HarvestState.INITIAL_PLACEMENT, q, np.array([0.0, 1.0, 0.0]))
    ended = clock.now()
    assert _pre_grasp_error(plant, config) > config.placement_tolerance
    while clock.now() < ended + 8 * TAU:  # hold what was sent
        servo.link.hold(out.q)
    assert _pre_grasp_error(plant, config) <= config.placement_tolerance


def _at_the_grasp(
    clock: FakeClock, servo: Servo, watch: BerryWatch
) -> tuple[np.ndarray, np.ndarray]:
    """The arm ramped to berry 1's grasp pose (through the model's gain error) and
    settled there: (q sent, the plan's q of the pre-grasp pose, on the nominal gain)."""
    config = servo.link.cfg
    axis = np.array([0.0, 1.0, 0.0])
    q_pre = (BERRIES[1] - (config.standoff + config.grasp_offset) * axis - P0) / K
    grasp_q = (BERRIES[1] - config.grasp_offset * axis - P0) / (GAIN_ERROR * K)
    q = servo.transport.ramp(watch, HarvestState.FINE_POSITIONING, np.zeros(3), grasp_q, 30.0)
    while clock.now() < 8 * TAU + 30.0 * PERIOD:  # the arm at the grasp pose, settled
        q = servo.link.hold(q)
    return q, q_pre


def _way_home(
    servo: Servo, watch: BerryWatch, q: np.ndarray, q_pre: np.ndarray
) -> tuple[np.ndarray, ...]:
    """The way go_home hands the transport after backing out from ``q`` with the plan
    ``(q_pre,)`` (the transport itself not run)."""
    ways: list[tuple[np.ndarray, ...]] = []

    def spy(watch, stage, q, way, start):  # type: ignore[no-untyped-def]
        ways.append(tuple(way))
        return q

    servo.transport.way_back = spy  # type: ignore[method-assign]
    home = np.full(3, 0.0167)
    axis = np.array([0.0, 1.0, 0.0])
    servo.go_home(watch, HarvestState.RETURN_HOME, q, home, axis, (q_pre,), BERRIES[1])
    return ways[0]


def test_the_way_home_leaves_from_the_back_out_not_from_the_plans_pre_grasp_q() -> None:
    """The back-out ends at the pre-grasp pose measured on the berry; the plan's q of
    that pose is the model's, whose pose is 2 cm off the arm's. The way home goes on
    from where the back-out left the arm, straight to the plan's next waypoint (home):
    before, its first leg sent the arm to the plan's q of the pre-grasp pose (the
    model's, 1-4 cm off it on the slow plant) and waited for it there."""
    clock, _, _, servo, watch, _ = _slow_rig(off=True)
    q, q_pre = _at_the_grasp(clock, servo, watch)
    way = _way_home(servo, watch, q, q_pre)
    assert len(way) == 1  # home alone


def test_the_back_out_hands_over_ahead_of_the_arm_only_within_2_cm() -> None:
    """The back-out ends on where the commands sent put the arm once the arm is measured
    within 2 cm of the pre-grasp pose (``BACK_OUT_AHEAD_WITHIN``): the way home begins while the
    arm is still farther than ``placement_tolerance`` out (before: 7 mm, once measured
    within it three steps in a row), but never while it is farther than 2 cm (ended
    ahead from anywhere, at 36 mm here: the way home cut the corner through the canes)."""
    clock, plant, _, servo, watch, _ = _slow_rig()
    config = servo.link.cfg
    q, q_pre = _at_the_grasp(clock, servo, watch)
    handed: list[float] = []

    def spy(watch, stage, q, way, start):  # type: ignore[no-untyped-def]
        handed.append(_pre_grasp_error(plant, config))
        return q

    servo.transport.way_back = spy  # type: ignore[method-assign]
    axis = np.array([0.0, 1.0, 0.0])
    servo.go_home(
        watch, HarvestState.RETURN_HOME, q, np.full(3, 0.0167), axis, (q_pre,), BERRIES[1]
    )
    assert config.placement_tolerance < handed[0] <= 0.02


def test_a_back_out_that_did_not_settle_goes_home_by_the_plans_way() -> None:
    """Without the cube the back-out ends short of the pre-grasp pose: the way home
    then retraces the plan from its pre-grasp q, the way it was checked along."""
    _, _, _, servo, watch, _ = _slow_rig()
    config = servo.link.cfg
    axis = np.array([0.0, 1.0, 0.0])
    q_pre = (BERRIES[1] - (config.standoff + config.grasp_offset) * axis - P0) / K
    grasp_q = (BERRIES[1] - config.grasp_offset * axis - P0) / (GAIN_ERROR * K)
    q = servo.transport.ramp(watch, HarvestState.FINE_POSITIONING, np.zeros(3), grasp_q, 30.0)
    servo.link.cfg = HarvestConfig(home_timeout=0.2)  # the back-out runs out of time
    way = _way_home(servo, watch, q, q_pre)
    assert len(way) == 2
    np.testing.assert_array_equal(way[0], q_pre)


def test_the_way_homes_last_leg_leaves_the_rest_of_the_way_to_the_ramp_home() -> None:
    """The last leg of the way home ends once the plan's point is home: the ramp home
    after it waits for the arm there. Before, the leg went on closing the loop until the
    arm was measured at the leg's end or the lag model had it there, then the ramp
    waited again."""
    clock, plant, _, servo, watch, log = _slow_rig(off=True)
    config = servo.link.cfg
    axis = np.array([0.0, 1.0, 0.0])
    q = (BERRIES[1] - (config.standoff + config.grasp_offset) * axis - P0) / K
    q = servo.transport.ramp(watch, HarvestState.INITIAL_PLACEMENT, np.zeros(3), q, 30.0)
    start = len(log.records)
    home = np.full(3, 0.0167)
    plan_steps = int(np.ceil(np.max(np.abs(home - q)) / (config.home_speed * config.period)))
    q = servo.transport.way_back(watch, HarvestState.RETURN_HOME, q, (home,), clock.now())
    steps = [r for r in log.records[start:] if r["kind"] == "step"]
    followed = [r for r in steps if r["goal"] is not None]  # the ramp has no goal
    assert len(followed) <= plan_steps + 1
    np.testing.assert_array_equal(q, home)
    np.testing.assert_allclose(
        plant.pressures(), home / METRES_PER_PSI, atol=config.arrival_tolerance / METRES_PER_PSI
    )
