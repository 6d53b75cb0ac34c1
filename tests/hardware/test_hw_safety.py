"""SafePressureBank: clamping, rate limit, watchdog, e-stop latch, vent on exit/exception,
and that nothing invalid ever reaches the backend (asserted on the recorded writes)."""

from __future__ import annotations

import logging
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import FakeClock
from softarm.errors import (
    HardwareError,
    HardwareUnavailableError,
    NonFiniteError,
    ParameterError,
    SafetyError,
    ShapeError,
)
from softarm.hardware.safety import SafePressureBank
from softarm.hardware.simulated import IdealPlant, SimulatedPressureBank

P_MAX = 60.0
RATE = 100.0  # psi/s
TIMEOUT = 0.5  # s


def make(clock: FakeClock) -> tuple[SafePressureBank, SimulatedPressureBank]:
    backend = SimulatedPressureBank(IdealPlant())
    safe = SafePressureBank(backend, P_MAX, RATE, TIMEOUT, clock=clock, watchdog_thread=False)
    return safe, backend


def ramp(safe: SafePressureBank, clock: FakeClock, target: np.ndarray, steps: int) -> None:
    for _ in range(steps):
        clock.advance(0.1)
        safe.set_pressures(target)


def test_startup_vents_and_first_command_only_starts_the_ramp(clock: FakeClock) -> None:
    safe, backend = make(clock)
    assert len(backend.writes) == 1 and not backend.writes[0].any()
    clock.advance(10.0)  # idle time must not allow a jump
    result = safe.set_pressures(np.full(9, 50.0))
    assert np.all(result.sent == 0.0) and result.rate_limited.all()


def test_clamps_to_zero_and_p_max_and_reports(clock: FakeClock, caplog) -> None:
    safe, backend = make(clock)
    request = np.array([-20.0, 0.0, 10.0, 59.0, 60.0, 61.0, 1e6, 30.0, -1e-9])
    safe.set_pressures(request)
    with caplog.at_level(logging.WARNING, logger="softarm.hardware.safety"):
        ramp(safe, clock, request, 20)  # 2 s at 100 psi/s: every channel reaches its target
    result = safe.set_pressures(request)
    expected = np.clip(request, 0.0, P_MAX)
    np.testing.assert_array_equal(result.sent, expected)
    np.testing.assert_array_equal(result.clamped, (request < 0.0) | (request > P_MAX))
    np.testing.assert_array_equal(backend.writes[-1], expected)
    assert "clamped channels [0, 5, 6, 8]" in caplog.text


def test_rate_limit_per_channel_uses_the_clock(clock: FakeClock) -> None:
    safe, backend = make(clock)
    safe.set_pressures(np.zeros(9))
    target = np.array([50.0, 5.0, 0, 0, 0, 0, 0, 0, 20.0])
    clock.advance(0.1)  # 10 psi allowed
    result = safe.set_pressures(target)
    np.testing.assert_allclose(result.sent, [10.0, 5.0, 0, 0, 0, 0, 0, 0, 10.0])
    np.testing.assert_array_equal(result.rate_limited, target - [10, 5, 0, 0, 0, 0, 0, 0, 10] > 0)
    clock.advance(0.05)  # 5 psi more
    np.testing.assert_allclose(safe.set_pressures(target).sent[[0, 8]], [15.0, 15.0])
    # Going down is limited too.
    clock.advance(0.02)
    np.testing.assert_allclose(safe.set_pressures(np.zeros(9)).sent[[0, 1, 8]], [13, 3, 13])
    assert backend.writes[-1][0] == pytest.approx(13.0)


def test_watchdog_vents_when_commands_stop(clock: FakeClock, caplog) -> None:
    safe, backend = make(clock)
    safe.set_pressures(np.zeros(9))
    ramp(safe, clock, np.full(9, 30.0), 5)
    assert backend.writes[-1][0] == pytest.approx(30.0)
    clock.advance(TIMEOUT * 0.9)
    assert safe.check_watchdog() is False
    clock.advance(TIMEOUT * 0.2)
    with caplog.at_level(logging.WARNING, logger="softarm.hardware.safety"):
        assert safe.check_watchdog() is True
    assert not backend.writes[-1].any()
    assert safe.vent_log[-1].reason.startswith("watchdog")
    assert "watchdog" in caplog.text
    n = len(backend.writes)
    clock.advance(10.0)
    assert safe.check_watchdog() is False  # vented once, not again and again
    assert len(backend.writes) == n


def test_late_command_is_preceded_by_a_watchdog_vent(clock: FakeClock) -> None:
    safe, _ = make(clock)
    safe.set_pressures(np.zeros(9))
    ramp(safe, clock, np.full(9, 30.0), 5)
    clock.advance(2 * TIMEOUT)
    result = safe.set_pressures(np.full(9, 30.0))
    assert safe.vent_log[-1].reason.startswith("watchdog")
    assert np.all(result.sent == 0.0)  # ramp restarts from the vented state


def test_watchdog_thread_vents_without_any_call() -> None:
    backend = SimulatedPressureBank(IdealPlant())
    with SafePressureBank(backend, P_MAX, 1000.0, watchdog_timeout_s=0.1) as safe:
        safe.set_pressures(np.zeros(9))
        time.sleep(0.02)
        safe.set_pressures(np.full(9, 20.0))
        assert backend.writes[-1][0] > 0.0
        deadline = time.monotonic() + 3.0
        while not safe.vent_log[-1].reason.startswith("watchdog"):
            assert time.monotonic() < deadline, "watchdog thread never vented"
            time.sleep(0.01)
        assert not backend.writes[-1].any()


def test_emergency_stop_latches_until_reset(clock: FakeClock) -> None:
    safe, backend = make(clock)
    safe.set_pressures(np.zeros(9))
    ramp(safe, clock, np.full(9, 30.0), 3)
    safe.emergency_stop("operator pressed the button")
    assert safe.stopped and not backend.writes[-1].any()
    n = len(backend.writes)
    clock.advance(0.1)
    with pytest.raises(SafetyError, match="emergency stop"):
        safe.set_pressures(np.full(9, 10.0))
    assert len(backend.writes) == n
    safe.reset()
    clock.advance(0.1)
    assert np.all(safe.set_pressures(np.full(9, 10.0)).sent == 0.0)  # ramp from zero
    clock.advance(0.05)
    assert safe.set_pressures(np.full(9, 10.0)).sent[0] == pytest.approx(5.0)


@pytest.mark.parametrize(
    ("bad", "error"),
    [
        (np.r_[np.full(8, 10.0), np.nan], NonFiniteError),
        (np.r_[np.inf, np.full(8, 10.0)], NonFiniteError),
        (np.r_[-np.inf, np.full(8, 10.0)], NonFiniteError),
        (np.full(8, 10.0), ShapeError),
        (np.full((9, 1), 10.0), ShapeError),
        (np.full(10, 10.0), ShapeError),
    ],
)
def test_invalid_commands_are_rejected_and_never_forwarded(
    clock: FakeClock, bad: np.ndarray, error: type[Exception]
) -> None:
    safe, backend = make(clock)
    safe.set_pressures(np.zeros(9))
    n = len(backend.writes)
    clock.advance(0.1)
    with pytest.raises(error, match="psi"):
        safe.set_pressures(bad)
    assert len(backend.writes) == n


def test_context_manager_vents_on_exit_and_on_exception(clock: FakeClock) -> None:
    backend = SimulatedPressureBank(IdealPlant())
    with SafePressureBank(backend, P_MAX, RATE, TIMEOUT, clock=clock, watchdog_thread=False) as s:
        s.set_pressures(np.zeros(9))
        ramp(s, clock, np.full(9, 20.0), 3)
    assert s.vent_log[-1].reason == "exit" and not backend.writes[-1].any()
    with pytest.raises(SafetyError, match="closed"):
        s.set_pressures(np.zeros(9))

    backend = SimulatedPressureBank(IdealPlant())
    with pytest.raises(RuntimeError, match="controller crashed"):
        with SafePressureBank(backend, P_MAX, RATE, TIMEOUT, clock=clock) as s:
            s.set_pressures(np.zeros(9))
            ramp(s, clock, np.full(9, 20.0), 3)
            raise RuntimeError("controller crashed")
    assert "controller crashed" in s.vent_log[-1].reason
    assert not backend.writes[-1].any()


def test_backend_failure_vents_and_raises_hardware_error(clock: FakeClock) -> None:
    safe, backend = make(clock)
    safe.set_pressures(np.zeros(9))
    ramp(safe, clock, np.full(9, 20.0), 2)
    backend.faults.error = HardwareError("regulator 4 lost power")
    with pytest.raises(HardwareError, match="regulator 4"):
        clock.advance(0.1)
        safe.set_pressures(np.full(9, 20.0))
    backend.faults.error = None
    assert "regulator 4" in safe.vent_log[-1].reason


def test_vent_failure_is_a_hardware_error(clock: FakeClock) -> None:
    safe, backend = make(clock)
    backend.faults.disconnected = True
    with pytest.raises(HardwareError, match="could not vent"):
        safe.vent("test")
    assert isinstance(HardwareUnavailableError("x"), HardwareError)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"p_max": 0.0}, "p_max"),
        ({"p_max": 80.0}, "exceeds"),
        ({"p_max": float("nan")}, "p_max"),
        ({"p_max": 1e300}, "p_max"),
        ({"p_max": True}, "p_max"),
        ({"max_rate_psi_per_s": -1.0}, "max_rate_psi_per_s"),
        ({"watchdog_timeout_s": float("inf")}, "watchdog_timeout_s"),
        # Issue 12: safety settings without upper bounds.
        (
            {"max_rate_psi_per_s": 1e308},
            r"max_rate_psi_per_s must be a finite number in \[0.1, 1000\]",
        ),
        ({"max_rate_psi_per_s": 0.01}, "max_rate_psi_per_s"),
        (
            {"watchdog_timeout_s": 1e308},
            r"watchdog_timeout_s must be a finite number in \[0.02, 10\]",
        ),
        ({"watchdog_timeout_s": 1e-300}, "watchdog_timeout_s"),
        ({"watchdog_timeout_s": "0.5"}, "watchdog_timeout_s"),
        ({"watchdog_timeout_s": complex(0.5, 0)}, "watchdog_timeout_s"),
    ],
)
def test_bad_parameters(kwargs: dict[str, float], name: str) -> None:
    args = {"p_max": P_MAX, "max_rate_psi_per_s": RATE, "watchdog_timeout_s": TIMEOUT} | kwargs
    with pytest.raises(ParameterError, match=name):
        SafePressureBank(SimulatedPressureBank(IdealPlant()), **args, watchdog_thread=False)


commands = st.lists(
    st.tuples(
        st.floats(0.0, 1.0),  # time step (s)
        st.lists(st.floats(-1e3, 1e3), min_size=9, max_size=9),
    ),
    max_size=30,
)


@settings(max_examples=60, deadline=None)
@given(commands)
def test_every_write_is_in_range_and_rate_limited(seq: list[tuple[float, list[float]]]) -> None:
    clock = FakeClock()
    safe, backend = make(clock)
    for dt, psi in seq:
        clock.advance(dt)
        before = len(backend.writes)
        last = backend.writes[-1].copy()
        safe.set_pressures(np.array(psi))
        vented = safe.vent_log[-1].time == clock.now and len(backend.writes) == before + 2
        step = backend.writes[-1] - (np.zeros(9) if vented else last)
        assert np.all(np.abs(step) <= RATE * min(dt, TIMEOUT) + 1e-9)
    for w in backend.writes:
        assert np.all((w >= 0.0) & (w <= P_MAX))
