"""SafePressureBank and the watchdog under the faults of issue 12: contending threads
against the rate limit (item 13), use after close (item 14), unbounded settings (item 12)."""

from __future__ import annotations

import random
import threading

import numpy as np
import pytest

from softarm.errors import HardwareError, ParameterError, SafetyError
from softarm.hardware.safety import SafePressureBank
from softarm.hardware.simulated import IdealPlant, SimulatedPressureBank
from softarm.hardware.watchdog import WatchdogThread

P_MAX = 60.0
RATE = 100.0  # psi/s


class JitterClock:
    """A thread-safe virtual clock: every reading lets a little time pass, and
    :meth:`wait` lets a random time pass (a DAQ write's latency)."""

    def __init__(self, seed: int) -> None:
        self._now = 100.0
        self._rng = random.Random(seed)
        self._lock = threading.Lock()

    def __call__(self) -> float:
        with self._lock:
            self._now += self._rng.uniform(0.0, 2e-4)
            return self._now

    def wait(self, longest: float) -> None:
        with self._lock:
            self._now += self._rng.uniform(0.0, longest)


class SlowBackend(SimulatedPressureBank):
    """A backend whose writes take effect after a random latency and return after
    another; it records the virtual time at which each output took effect."""

    def __init__(self, clock: JitterClock) -> None:
        super().__init__(IdealPlant())
        self.clock = clock
        self.times: list[float] = []

    def set_pressures(self, psi: np.ndarray) -> None:
        self.clock.wait(5e-3)  # the driver call before the output changes
        super().set_pressures(psi)
        self.times.append(self.clock())
        self.clock.wait(5e-3)  # the driver call returning


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_contending_threads_never_exceed_the_rate_at_the_backend(seed: int) -> None:
    """Issue 12 item 13: the rate limit was stamped when a command was decided, so a
    slow write followed by a fast one exceeded the rate at the backend. Eight threads
    race here; every pair of consecutive outputs must respect |dp| <= rate * dt."""
    clock = JitterClock(seed)
    backend = SlowBackend(clock)
    safe = SafePressureBank(backend, P_MAX, RATE, 0.5, clock, watchdog_thread=False)
    rng = np.random.default_rng(seed)
    targets = rng.uniform(0.0, P_MAX, size=(8, 40, 9))
    errors: list[BaseException] = []

    def worker(mine: np.ndarray) -> None:
        try:
            for target in mine:
                safe.set_pressures(target)
        except BaseException as exc:  # reported below: a thread must not fail silently
            errors.append(exc)

    threads = [threading.Thread(target=worker, args=(targets[i],)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert len(safe.vent_log) == 1  # only the startup vent: every write below is a command
    writes = np.array(backend.writes)
    times = np.array(backend.times)
    assert len(writes) == 1 + 8 * 40
    steps = np.abs(np.diff(writes, axis=0)).max(axis=1)
    allowed = RATE * np.diff(times)
    assert np.all(steps <= allowed + 1e-9), f"worst excess {np.max(steps - allowed):.4f} psi"
    assert steps.max() > 0.0  # the arm did move


def test_vent_and_emergency_stop_after_close_do_not_call_the_backend() -> None:
    backend = SimulatedPressureBank(IdealPlant())
    safe = SafePressureBank(backend, P_MAX, RATE, 0.5, watchdog_thread=False)
    safe.close()
    assert backend.closed
    n, events = len(backend.writes), len(safe.vent_log)
    safe.vent("late vent")  # documented: a no-op, never an exception on a stop path
    safe.emergency_stop("late stop")
    assert safe.stopped  # the latch is still set
    assert len(backend.writes) == n and len(safe.vent_log) == events
    assert safe.check_watchdog() is False
    with pytest.raises(SafetyError, match="closed"):
        safe.read_pressures()
    with pytest.raises(SafetyError, match="closed"):
        safe.set_pressures(np.zeros(9))
    with pytest.raises(SafetyError, match="closed"):
        safe.reset()
    safe.close()  # twice is harmless


def test_a_closed_simulated_bank_refuses_use() -> None:
    backend = SimulatedPressureBank(IdealPlant())
    backend.close()
    for call in (backend.vent, backend.read_pressures, lambda: backend.set_pressures(np.zeros(9))):
        with pytest.raises(HardwareError, match="closed"):
            call()
    backend.close()


@pytest.mark.parametrize("period", [1e308, 1e-300, float("nan"), float("inf"), 0.0, -1.0, "1"])
def test_watchdog_period_is_bounded(period: object) -> None:
    """1e308 raised OverflowError inside Event.wait, outside the thread's try, and the
    watchdog thread died; 1e-300 made it spin."""
    with pytest.raises(ParameterError, match="watchdog period_s"):
        WatchdogThread(lambda: None, period, name="test")  # type: ignore[arg-type]


def test_the_longest_allowed_watchdog_keeps_its_thread_alive() -> None:
    backend = SimulatedPressureBank(IdealPlant())
    with SafePressureBank(backend, P_MAX, RATE, watchdog_timeout_s=10.0) as safe:
        assert safe._thread is not None and safe._thread.running
    assert not safe._thread.running
