"""SIGTERM and SIGINT as an exception, so that a run being stopped unwinds through its
``finally`` blocks (vent the arm, close the devices, sync the log) instead of dying
where it stands. Python's default SIGTERM action ends the process at once, with no
cleanup at all; SIGINT raises KeyboardInterrupt, which prints a traceback.

Every command that can pressurise the arm gets the same handling from here:

* :func:`drives_arm` decorates its ``run(args)``: the signals raise :class:`Interrupted`,
  and the command ends with one line on stderr and exit status 130 or 143;
* :func:`vents_on_stop` wraps the part that drives the arm: a stop vents it and, given
  a run log, records why (``interrupted``) and syncs the log;
* :func:`records_late_stop` wraps what a run writes after it ended: a stop then is
  recorded in the run's log too.

Commands that only write files get :func:`stops_on_signals`: a stop unwinds through
their clean-up and ends them with one line, exit status 130 or 143.
"""

from __future__ import annotations

import functools
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any, Protocol

from softarm.uninterrupted import defer

__all__ = [
    "Interrupted",
    "drives_arm",
    "raise_on_signals",
    "records_late_stop",
    "stop_arm",
    "stops_on_signals",
    "vents_on_stop",
]

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
    if defer(functools.partial(_stop, signum)):  # inside a section that must not be cut
        return
    raise Interrupted(signum)


def _stop(signum: int) -> None:
    raise Interrupted(signum)


@contextmanager
def raise_on_signals() -> Iterator[None]:
    """Inside the block, SIGINT and SIGTERM raise :class:`Interrupted`; the previous
    handlers are restored on the way out. Only the main thread can install handlers, so
    elsewhere (a test runner's worker thread) the block runs unchanged.

    A signal that arrives while a finalizer runs (``__del__``, as when a harvest's
    renderers are freed) raises inside it, and Python only prints "Exception ignored"
    and goes on: the stop would be lost and the command exit 0. Such a swallowed stop
    is kept (:func:`_keep_swallowed`) and signalled again once the finalizer returned,
    or raised when the block ends first, so the command still ends as stopped."""
    try:
        previous = {s: signal.signal(s, _raise) for s in SIGNALS}
    except ValueError:  # not the main thread
        yield
        return
    swallowed: list[Interrupted] = []
    resends: list[threading.Timer] = []
    hook = sys.unraisablehook
    sys.unraisablehook = _keep_swallowed(swallowed, resends, hook)
    try:
        yield
    finally:
        sys.unraisablehook = hook
        if resends:  # the stop is raised below: a resent signal must not land later
            for s in SIGNALS:
                signal.signal(s, signal.SIG_IGN)
            for timer in resends:
                timer.cancel()
                timer.join()
        for s, handler in previous.items():
            signal.signal(s, handler)
    if swallowed:
        raise swallowed[0]


#: How soon (s) a stop a finalizer swallowed is signalled again, once it has returned.
RESEND_S = 0.05


def _keep_swallowed(
    swallowed: list[Interrupted], resends: list[threading.Timer], hook: Callable[[Any], object]
) -> Callable[[Any], object]:
    """An unraisable hook that keeps an :class:`Interrupted` a finalizer swallowed (not
    printed: the stop is reported once, as a stop) and passes anything else to ``hook``.
    The kept stop is signalled again shortly, so that a run does not go on to its end
    (the handlers are armed again: :func:`_raise` had set them to ignore)."""

    def keep(unraisable: Any) -> object:
        exc = unraisable.exc_value
        if not isinstance(exc, Interrupted):
            return hook(unraisable)
        swallowed.append(exc)
        for s in SIGNALS:
            signal.signal(s, _raise)
        timer = threading.Timer(RESEND_S, os.kill, (os.getpid(), exc.signum))
        timer.daemon = True
        resends.append(timer)
        timer.start()
        return None

    return keep


class EventLog(Protocol):
    """What a stop writes to: :class:`softarm.harvest.records.log.HarvestLog` is one."""

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


class ReopenableLog(EventLog, Protocol):
    """A log that can be opened again for a record after the run closed it."""

    def reopen(self) -> None: ...


@contextmanager
def records_late_stop(log: ReopenableLog) -> Iterator[None]:
    """After a run, while its outputs (report, bag, plot) are written: a stop is recorded
    in the run's ``log``, opened again for it, so that a run stopped now still ends its
    log with the ``interrupted`` record. The arm was vented when the run ended."""
    try:
        yield
    except (Interrupted, KeyboardInterrupt, SystemExit) as exc:
        log.reopen()
        stop_arm(lambda reason: None, exc, log)
        raise


Run = Callable[[Any], int]


def stops_on_signals(run: Run) -> Run:
    """Decorator for the ``run(args)`` of a command that writes files but drives no arm
    (``dataset``, ``replay``): SIGINT and SIGTERM raise :class:`Interrupted`, so its
    ``finally`` blocks remove what it left half-written, and ``softarm.cli.main`` ends it
    with one line and exit status 130 or 143. Python's default SIGTERM ends the process
    where it stands, temporary files and folders left behind."""

    @functools.wraps(run)
    def guarded(args: Any) -> int:
        with raise_on_signals():
            return run(args)

    return guarded


def drives_arm(command: str) -> Callable[[Run], Run]:
    """Decorator for the ``run(args)`` of a command that can pressurise the arm: while it
    runs, SIGINT and SIGTERM raise :class:`Interrupted` (its ``finally`` blocks and
    :func:`vents_on_stop` vent the arm), and the stop ends the command with one line on
    stderr and exit status 128 + the signal number, never a traceback."""

    def decorate(run: Run) -> Run:
        @functools.wraps(run)
        def guarded(args: Any) -> int:
            try:
                with raise_on_signals():  # its end may raise a stop a finalizer swallowed
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
