"""SIGTERM and SIGINT as an exception, so that a run being stopped unwinds through its
``finally`` blocks (vent the arm, close the devices, sync the log) instead of dying
where it stands. Python's default SIGTERM action ends the process at once, with no
cleanup at all; SIGINT raises KeyboardInterrupt, which prints a traceback.

Every command that can pressurise the arm gets the same handling from here:

* :func:`drives_arm` decorates its ``run(args)``: the signals raise :class:`Interrupted`,
  and the command ends with one line on stderr and exit status 130 or 143;
* :func:`vents_on_stop` wraps the part that drives the arm: a stop vents it and, given
  a run log, records why (``interrupted``) and syncs the log.
"""

from __future__ import annotations

import functools
import logging
import signal
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any, Protocol

__all__ = ["Interrupted", "drives_arm", "raise_on_signals", "stop_arm", "vents_on_stop"]

_log = logging.getLogger(__name__)

#: Handled signals and the exit status a shell reports for them (128 + number).
SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupted(BaseException):
    """A stop request arrived. A BaseException like KeyboardInterrupt, so that the
    ``except Exception`` handlers of device code cannot swallow it."""

    def __init__(self, signum: int) -> None:
        self.signum = signum
        self.name = signal.Signals(signum).name
        super().__init__(f"interrupted by {self.name}")

    @property
    def exit_status(self) -> int:
        """128 + the signal number: 130 for SIGINT, 143 for SIGTERM."""
        return 128 + self.signum


def _raise(signum: int, frame: FrameType | None) -> None:
    # Ignore repeats while the first one is being handled: a second Ctrl-C must not cut
    # the venting short. SIGKILL still ends everything.
    for s in SIGNALS:
        signal.signal(s, signal.SIG_IGN)
    raise Interrupted(signum)


@contextmanager
def raise_on_signals() -> Iterator[None]:
    """Inside the block, SIGINT and SIGTERM raise :class:`Interrupted`; the previous
    handlers are restored on the way out. Only the main thread can install handlers, so
    elsewhere (a test runner's worker thread) the block runs unchanged."""
    try:
        previous = {s: signal.signal(s, _raise) for s in SIGNALS}
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


class EventLog(Protocol):
    """What a stop writes to: :class:`softarm.harvest.log.HarvestLog` is one."""

    def event(self, kind: str, **fields: Any) -> None: ...

    def close(self) -> None: ...


def _signal_of(exc: BaseException) -> signal.Signals | None:
    """The signal behind a stop: ours (:class:`Interrupted`), Python's own SIGINT
    (KeyboardInterrupt), or a host's handler that exits with the signal's number (Ray's
    workers do ``sys.exit(SIGTERM)``)."""
    if isinstance(exc, Interrupted):
        return signal.Signals(exc.signum)
    if isinstance(exc, KeyboardInterrupt):
        return signal.SIGINT
    if isinstance(exc, SystemExit) and exc.code in SIGNALS:
        return signal.Signals(exc.code)
    return None


def stop_arm(vent: Callable[[str], object], exc: BaseException, log: EventLog | None) -> bool:
    """Vent the arm because of the stop ``exc``, and record it in ``log`` (then close the
    log, which syncs it). Never raises: the log must be completed even when the driver is
    dead. Returns whether the vent succeeded."""
    sig = _signal_of(exc)
    reason = f"stopped by {sig.name if sig else type(exc).__name__}"
    try:
        vent(reason)
        vented = True
    except Exception as err:  # a dead driver: still record why the run ended
        _log.error("vent failed after %s: %r", reason, err)
        if log is not None:
            log.event("vent_failed", error=repr(err))
        vented = False
    if log is not None:
        log.event(
            "interrupted",
            signal=sig.name if sig else None,
            reason=reason,
            vented=vented,
            exit_status=128 + sig.value if sig else None,
        )
        log.close()
        # The exit message names the log only once the stop is recorded in it.
        exc.written_log = getattr(log, "path", None)  # type: ignore[attr-defined]
    return vented


@contextmanager
def vents_on_stop(vent: Callable[[str], object], log: EventLog | None = None) -> Iterator[None]:
    """Inside the block, a stop (a signal, or a host's exit) vents the arm with
    :func:`stop_arm` and goes on up. Ordinary exceptions are left to the code that drives
    the arm: its own fault handling vents and logs them."""
    try:
        yield
    except (Interrupted, KeyboardInterrupt, SystemExit) as exc:
        stop_arm(vent, exc, log)
        raise


Run = Callable[[Any], int]


def drives_arm(command: str) -> Callable[[Run], Run]:
    """Decorator for the ``run(args)`` of a command that can pressurise the arm: while it
    runs, SIGINT and SIGTERM raise :class:`Interrupted` (its ``finally`` blocks and
    :func:`vents_on_stop` vent the arm), and the stop ends the command with one line on
    stderr and exit status 128 + the signal number, never a traceback."""

    def decorate(run: Run) -> Run:
        @functools.wraps(run)
        def guarded(args: Any) -> int:
            with raise_on_signals():
                try:
                    return run(args)
                except Interrupted as exc:
                    log = getattr(exc, "written_log", None)  # set by stop_arm
                    where = f"; log {log}" if log else ""
                    _log.info("softarm %s %s: arm vented", command, exc)
                    print(f"softarm {command}: {exc}: arm vented{where}", file=sys.stderr)
                    return exc.exit_status

        guarded.drives_arm = True  # type: ignore[attr-defined]
        return guarded

    return decorate
