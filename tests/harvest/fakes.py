"""Fast fakes of the harvest interfaces: a 3-actuator 'arm' whose end effector translates
by K·q, facing +Y, driven through the real safety layer and simulated pressure bank."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from softarm.hardware import SafePressureBank, SimulatedPressureBank
from softarm.hardware.pressure_map import METRES_PER_PSI
from softarm.harvest import (
    BerryFix,
    BerryTarget,
    HarvestConfig,
    HarvestLog,
    HarvestMachine,
    Observation,
    SafeActuator,
)
from softarm.harvest.machine.states import HarvestState

K = 3.0  # metres of end-effector travel per metre of elongation
P0 = np.array([-0.05, 0.25, 0.25])  # end effector when vented
Q_MAX = 70.0 * METRES_PER_PSI
FACING_Y = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])  # z axis along +Y


class FakeClock:
    """Simulated time; ``hooks`` run at every tick (to inject faults at a given time)."""

    def __init__(self) -> None:
        self.t = 0.0
        self.hooks: list[Callable[[float], None]] = []

    def now(self) -> float:
        return self.t

    def sleep(self, dt: float) -> None:
        self.t += dt
        for hook in self.hooks:
            hook(self.t)


class FakePlant:
    """Pressures follow the command instantly; the pose follows the pressures."""

    def __init__(self) -> None:
        self.psi = np.zeros(3)

    def command_pressures(self, psi: np.ndarray) -> None:
        self.psi = np.array(psi, dtype=np.float64)

    def pressures(self) -> np.ndarray:
        return self.psi.copy()

    def pose(self) -> np.ndarray:
        out = np.eye(4)
        out[:3, :3] = FACING_Y
        out[:3, 3] = P0 + K * self.psi * METRES_PER_PSI
        return out


@dataclass
class FakeTracker:
    """The true pose, except while ``blind(t)``; ``nan_after`` poisons it."""

    plant: FakePlant
    blind: Callable[[float], bool] = lambda t: False
    nan_after: float = np.inf
    crash_after: float = np.inf

    def track(self, time: float) -> np.ndarray | None:
        if time >= self.crash_after:
            raise RuntimeError("simulated bug in the tracker")
        if self.blind(time):
            return None
        pose = self.plant.pose()
        if time >= self.nan_after:
            pose[0, 3] = np.nan
        return pose


@dataclass
class FakeLocator:
    """Berries by tag id; eye-to-hand beyond 6 cm, eye-in-hand within; while ``hidden(t)``
    the last fix is held for up to ``max_age`` s."""

    berries: dict[int, np.ndarray]
    hidden: Callable[[float], bool] = lambda t: False
    max_age: float = 1.0
    selected: int = -1
    _last: tuple[np.ndarray, float] | None = field(default=None)

    def select(self, berry: BerryTarget) -> None:
        self.selected, self._last = berry.tag_id, None

    def locate(self, time: float, T_base_ee: np.ndarray | None) -> BerryFix | None:
        if self.hidden(time):
            if self._last is not None and time - self._last[1] <= self.max_age:
                return BerryFix(self._last[0], "held", time - self._last[1])
            return None
        p = self.berries[self.selected]
        near = T_base_ee is not None and np.linalg.norm(p - T_base_ee[:3, 3]) < 0.06
        self._last = (p, time)
        return BerryFix(p.copy(), "eye_in_hand" if near else "eye_to_hand")


@dataclass
class FakeVision:
    """Both fakes as one :class:`~softarm.harvest.machine.interfaces.Vision`: the pose, then the
    berry given that pose."""

    tracker: FakeTracker
    locator: FakeLocator

    def select(self, berry: BerryTarget) -> None:
        self.locator.select(berry)

    def observe(self, time: float, need_fix: bool = True) -> Observation:
        pose = self.tracker.track(time)
        return Observation(time, pose, self.locator.locate(time, pose))


@dataclass
class FakeController:
    """Proportional step in q towards the target position, clipped to the limits."""

    gain: float = 0.5

    def step(self, q: np.ndarray, target: np.ndarray, current: np.ndarray | None):
        assert current is not None
        raw = q + self.gain * (target[:3, 3] - current[:3, 3]) / K
        q_next = np.clip(raw, 0.0, Q_MAX)
        return q_next, bool(np.any(q_next != raw))

    def follow_step(self, q: np.ndarray, target: np.ndarray, current: np.ndarray):
        return self.step(q, target, current)

    def model_pose(self, q: np.ndarray) -> np.ndarray:
        """The fake arm's pose at ``q`` (the plant's, exactly: the model has no error)."""
        out = np.eye(4)
        out[:3, :3] = FACING_Y
        out[:3, 3] = P0 + K * np.asarray(q, dtype=np.float64)
        return out

    def limits(self) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(3), np.full(3, Q_MAX)

    def way_gaps(self, q0: np.ndarray, q1: np.ndarray, steps: int = 8) -> None:
        return None  # no known canes


@dataclass
class FakeGripper:
    closed: bool = False
    fail_on_close: Exception | None = None

    @property
    def position(self) -> float:
        return 1.0 if self.closed else 0.0

    def open(self) -> None:
        self.closed = False

    def close(self) -> None:
        if self.fail_on_close is not None:
            raise self.fail_on_close
        self.closed = True


@dataclass
class FakeRipeness:
    values: dict[int, float]
    locator: FakeLocator

    def read(self) -> float:
        return self.values.get(self.locator.selected, 1.0)


@dataclass
class Rig:
    """Everything wired; ``machine`` is ready to run."""

    clock: FakeClock
    plant: FakePlant
    backend: SimulatedPressureBank
    bank: SafePressureBank
    tracker: FakeTracker
    locator: FakeLocator
    gripper: FakeGripper
    ripeness: FakeRipeness
    machine: HarvestMachine

    def vented(self) -> bool:
        """All channels at 0 psi, and the safety layer logged a vent after startup."""
        return bool(np.all(self.plant.psi == 0.0)) and len(self.bank.vent_log) > 1

    def transitions(self, berry: int | None = None) -> list[HarvestState]:
        recs = self.machine.log.records
        return [
            HarvestState(r["new"])
            for r in recs
            if r["kind"] == "transition" and (berry is None or r["berry"] == berry)
        ]


#: Reachable berries (grasp and pre-grasp poses inside the fake workspace) and one not.
BERRIES = {
    1: np.array([0.0, 0.35, 0.30]),
    2: np.array([0.02, 0.36, 0.28]),
    3: np.array([0.0, 0.50, 0.30]),  # 12 cm too far along +Y: saturates
}


def make_rig(log: HarvestLog | None = None, config: HarvestConfig | None = None) -> Rig:
    clock = FakeClock()
    plant = FakePlant()
    backend = SimulatedPressureBank(plant, channels=3)
    bank = SafePressureBank(backend, 70.0, 100.0, 0.5, clock.now, watchdog_thread=False)
    tracker = FakeTracker(plant)
    locator = FakeLocator(dict(BERRIES))
    gripper = FakeGripper()
    ripeness = FakeRipeness({}, locator)
    machine = HarvestMachine(
        clock,
        FakeVision(tracker, locator),
        FakeController(),
        SafeActuator(bank),
        gripper,
        ripeness,
        n_actuators=3,
        config=config or HarvestConfig(marker_timeout=0.5, stall_time=1.0),
        log=log,
    )
    return Rig(clock, plant, backend, bank, tracker, locator, gripper, ripeness, machine)


def commanded_before_the_vent(rig) -> list[float]:
    """The q of the last step logged before the fault's vent."""
    records = rig.machine.log.records
    at = next(i for i, r in enumerate(records) if r["kind"] == "vent")
    return next(r["q"] for r in reversed(records[:at]) if r["kind"] == "step")
