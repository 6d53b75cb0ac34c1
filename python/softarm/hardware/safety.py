"""The safety layer that stands in front of every pressure backend.

:class:`SafePressureBank` wraps any :class:`~softarm.hardware.protocols.PressureBank`
and guarantees that nothing outside ``[0, p_max]`` psi, nothing non-finite and nothing of
the wrong shape ever reaches it. It also limits how fast each channel may change, vents
every channel when commands stop arriving (watchdog), latches an emergency stop, and
vents on exit and on exception when used as a context manager. Every vent is logged
with its reason and kept in :attr:`SafePressureBank.vent_log`.
"""

from __future__ import annotations

import logging
import math
import numbers
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from types import TracebackType

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray, numeric_array
from softarm.errors import (
    HardwareError,
    NonFiniteError,
    ParameterError,
    SafetyError,
    ShapeError,
)
from softarm.hardware.limits import FULL_SCALE_PSI, MAX_RATE_PSI_PER_S, WATCHDOG_TIMEOUT_S
from softarm.hardware.protocols import PressureBank
from softarm.hardware.watchdog import WatchdogThread

__all__ = ["CommandResult", "SafePressureBank", "VentEvent"]

BoolArray = npt.NDArray[np.bool_]

_log = logging.getLogger(__name__)


def _is_real(value: object) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


@dataclass(frozen=True)
class CommandResult:
    """What :meth:`SafePressureBank.set_pressures` did with one command.

    Attributes:
        requested: the command as given (psi).
        sent: what was forwarded to the backend (psi), always within ``[0, p_max]``.
        clamped: per channel, whether the request lay outside ``[0, p_max]``.
        rate_limited: per channel, whether the rate limit shortened the step.
    """

    requested: FloatArray
    sent: FloatArray
    clamped: BoolArray
    rate_limited: BoolArray

    @property
    def modified(self) -> bool:
        """Whether ``sent`` differs from ``requested`` on any channel."""
        return bool(self.clamped.any() or self.rate_limited.any())


@dataclass(frozen=True)
class VentEvent:
    """One vent: the clock time and why."""

    time: float
    reason: str


class SafePressureBank:
    """Clamp, rate-limit and watch the commands sent to a pressure backend.

    The backend is vented when the wrapper is created, so the rate limit starts from a
    known state (0 psi everywhere). After startup, a vent or :meth:`reset`, the first
    command forwards the current pressures unchanged and starts the ramp: pressures then
    rise by at most ``max_rate_psi_per_s`` times the time between commands (that time
    capped at ``watchdog_timeout_s``).

    Args:
        backend: the pressure bank to protect.
        p_max: highest pressure (psi) ever forwarded; in (0, 150] and not above
            ``backend.max_pressure``.
        max_rate_psi_per_s: largest change per channel per second, both directions
            (a sudden drop whips the arm as much as a sudden rise), in [0.1, 1000].
            Venting is exempt.
        watchdog_timeout_s: vent when no command has arrived for this long, in
            [0.02, 10] s. The ranges and their reasons are in
            :mod:`softarm.hardware.limits`.
        clock: monotonic time source in seconds; inject a fake one in tests.
        watchdog_thread: run a daemon thread that checks the watchdog every
            ``watchdog_timeout_s / 4`` s. Without it the watchdog is checked only on
            each call and by :meth:`check_watchdog`.
        simulated: the backend is a simulated arm: a vent's warning says "simulated arm
            vented", not "venting all N channels".

    Raises:
        ParameterError: a limit is not a finite number inside its range.

    After :meth:`close`, commands and :meth:`read_pressures` raise :class:`SafetyError`;
    :meth:`vent` and :meth:`emergency_stop` are no-ops (the bank was vented when it
    closed, and a closed backend must not be called): a stop path never raises.
    """

    def __init__(
        self,
        backend: PressureBank,
        p_max: float,
        max_rate_psi_per_s: float,
        watchdog_timeout_s: float,
        clock: Callable[[], float] = time.monotonic,
        *,
        watchdog_thread: bool = True,
        simulated: bool = False,
    ) -> None:
        rate = MAX_RATE_PSI_PER_S.check(max_rate_psi_per_s)
        timeout = WATCHDOG_TIMEOUT_S.check(watchdog_timeout_s)
        if not (_is_real(p_max) and math.isfinite(p_max) and 0.0 < p_max <= FULL_SCALE_PSI.hi):
            raise ParameterError(
                f"p_max must be a finite number in (0, {FULL_SCALE_PSI.hi:g}] psi "
                f"({FULL_SCALE_PSI.why}), got {p_max!r}"
            )
        if p_max > backend.max_pressure:
            raise ParameterError(
                f"p_max={p_max!r} psi exceeds the backend's max_pressure="
                f"{backend.max_pressure!r} psi"
            )
        self._backend = backend
        self._p_max = float(p_max)
        self._rate = rate
        self._timeout = timeout
        self._clock = clock
        self._lock = threading.RLock()
        self._n = int(backend.channels)
        # What a vent's warning names: a simulated arm's is no valve opening.
        self._vented = "simulated arm vented" if simulated else f"venting all {self._n} channels"
        self._last = np.zeros(self._n)
        self._last_time = clock()
        self._armed = False  # a command is live: the watchdog may fire
        self._latched = False
        self._closed = False
        self.vent_log: list[VentEvent] = []
        self.vent("startup", level=logging.INFO)  # the normal start, not a warning
        self._thread: WatchdogThread | None = None
        if watchdog_thread:
            self._thread = WatchdogThread(
                self.check_watchdog, self._timeout / 4.0, name="softarm-pressure-watchdog"
            )
            self._thread.start()

    @property
    def channels(self) -> int:
        """Number of channels of the backend."""
        return self._n

    @property
    def max_pressure(self) -> float:
        """The safety limit ``p_max`` (psi)."""
        return self._p_max

    @property
    def max_rate(self) -> float:
        """The rate limit (psi/s) every command is held to."""
        return self._rate

    @property
    def stopped(self) -> bool:
        """Whether the emergency stop is latched."""
        return self._latched

    @property
    def last_sent(self) -> FloatArray:
        """The last pressures forwarded to the backend (psi), a copy."""
        with self._lock:
            return self._last.copy()

    def set_pressures(self, psi: npt.ArrayLike) -> CommandResult:
        """Validate, clamp and rate-limit ``psi`` (shape ``(channels,)``), then forward it.

        Raises:
            SafetyError: the emergency stop is latched or the bank is closed.
            ShapeError: ``psi`` is not numbers (text, complex, a dict...) or does not
                have shape ``(channels,)``.
            NonFiniteError: ``psi`` contains NaN, inf or a number beyond the float
                range. Nothing is forwarded.
        """
        requested = numeric_array(psi, "psi")
        if requested.shape != (self._n,):
            raise ShapeError(f"psi must have shape ({self._n},), got {requested.shape}")
        if not np.all(np.isfinite(requested)):
            bad = np.flatnonzero(~np.isfinite(requested)).tolist()
            raise NonFiniteError(f"psi must be finite, channels {bad} are {requested[bad]}")
        with self._lock:
            self._refuse_if_stopped()
            self.check_watchdog()
            now = self._clock()
            target = np.clip(requested, 0.0, self._p_max)
            clamped = target != requested
            # After a vent, startup or reset the first command only starts the ramp clock:
            # time spent idle must not buy a large jump.
            dt = min(max(now - self._last_time, 0.0), self._timeout) if self._armed else 0.0
            max_step = self._rate * dt
            step = np.clip(target - self._last, -max_step, max_step)
            rate_limited = step != target - self._last
            # The clip is redundant (last and target are in range) but makes the bound local.
            sent = np.clip(self._last + step, 0.0, self._p_max)
            try:
                self._backend.set_pressures(sent)
            except Exception as exc:
                self.vent(f"backend error on set_pressures: {exc!r}")
                if isinstance(exc, HardwareError):
                    raise
                raise HardwareError(f"pressure backend failed: {exc!r}") from exc
            self._last = sent
            # Stamp the rate limit *after* the write returns, not at ``now`` (when the
            # step was decided): the output took effect somewhere inside the write, so
            # the next command's Δt = its decision time − this stamp never exceeds the
            # real time between the two outputs, however long a write takes.
            self._last_time = self._clock()
            self._armed = True
        result = CommandResult(requested, sent.copy(), clamped, rate_limited)
        if clamped.any():
            _log.warning(
                "clamped channels %s to [0, %g] psi: requested %s",
                np.flatnonzero(clamped).tolist(),
                self._p_max,
                requested[clamped].tolist(),
            )
        return result

    def read_pressures(self) -> FloatArray:
        """The backend's pressures (psi).

        Raises:
            SafetyError: the bank is closed (the backend is gone).
        """
        with self._lock:
            if self._closed:
                raise SafetyError("pressure bank is closed; cannot read pressures")
            return self._backend.read_pressures()

    def check_watchdog(self) -> bool:
        """Vent if a command is live and none has arrived for ``watchdog_timeout_s``.

        Returns whether it vented. Called by the watchdog thread and on every command.
        """
        with self._lock:
            if not self._armed or self._closed:
                return False
            idle = self._clock() - self._last_time
            if idle <= self._timeout:
                return False
            self.vent(f"watchdog: no command for {idle:.3f} s (timeout {self._timeout} s)")
            return True

    def vent(self, reason: str = "requested", *, level: int = logging.WARNING) -> None:
        """Vent every channel now (no rate limit) and log ``reason``.

        If the backend's ``vent`` fails, zero pressures are commanded instead; if that
        fails too, :class:`HardwareError` is raised. After :meth:`close` it does nothing
        (the bank was vented when it closed; the backend must not be called again).
        """
        with self._lock:
            if self._closed:
                _log.info("vent (%s) ignored: the pressure bank is closed and vented", reason)
                return
            now = self._clock()
            self.vent_log.append(VentEvent(now, reason))
            _log.log(level, "%s: %s", self._vented, reason)
            try:
                self._backend.vent()
            except Exception as exc:
                _log.error("backend vent failed (%r); commanding 0 psi instead", exc)
                try:
                    self._backend.set_pressures(np.zeros(self._n))
                except Exception as exc2:
                    raise HardwareError(
                        f"could not vent: vent() raised {exc!r}, set_pressures(0) raised {exc2!r}"
                    ) from exc2
            self._last = np.zeros(self._n)
            self._last_time = now
            self._armed = False

    def emergency_stop(self, reason: str = "emergency stop") -> None:
        """Vent and latch: every further command raises :class:`SafetyError` until
        :meth:`reset`. After :meth:`close` it only latches (see :meth:`vent`)."""
        with self._lock:
            self._latched = True
            self.vent(f"emergency stop: {reason}")

    def reset(self) -> None:
        """Clear the emergency-stop latch. Pressures restart from 0 under the rate limit."""
        with self._lock:
            if self._closed:
                raise SafetyError("cannot reset: the pressure bank is closed")
            self._latched = False
            self._last_time = self._clock()
            _log.warning("emergency stop reset")

    def close(self, reason: str = "close") -> None:
        """Stop the watchdog, vent and close the backend. Calling it twice is harmless."""
        if self._thread is not None:
            self._thread.stop()
        with self._lock:
            if self._closed:
                return
            try:
                self.vent(reason)
            finally:
                self._closed = True
                self._backend.close()

    def __enter__(self) -> SafePressureBank:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close("exit" if exc is None else f"exception: {exc!r}")

    def _refuse_if_stopped(self) -> None:
        if self._closed:
            raise SafetyError("pressure bank is closed; command refused")
        if self._latched:
            raise SafetyError("emergency stop is latched; call reset() before commanding")
