"""The dataset's images rendered as Ray tasks on a private local Ray
(:func:`softarm.sim.render.dataset.write_dataset` uses it when Ray is installed).

Two things a plain ``ray.wait`` loop gets wrong:

* Submission is bounded: at most :data:`IN_FLIGHT_PER_WORKER` tasks per worker are
  submitted at a time, the next one as each finishes. Submitting every task up front
  makes the driver hold a task record per image (``--images 1000000`` grew it by about
  60 MB/s).
* ``ray.init`` replaces the driver's SIGTERM handler with one that calls ``sys.exit``,
  and a SIGTERM then tore Ray down mid-call (exit 134, a C++ stack dump). The handler
  in place before (``softarm dataset``'s: raise :class:`~softarm.commands._signals.
  Interrupted`) is put back. An exception raised by a handler inside ``ray.wait``
  (Ray runs the handlers from its C++ loop) comes out as a ``SystemError``, so while
  the tasks run a stop is only noted (:class:`_Stops`), ``ray.wait`` wakes every
  :data:`WAKE_S`, and the stop is handed to that handler between two waits: it unwinds
  through ``ray.shutdown``.
"""

from __future__ import annotations

import logging
import os
import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from softarm.errors import SoftarmError

__all__ = ["IN_FLIGHT_PER_WORKER", "on_ray", "ray_or_none"]

#: Tasks submitted at a time per worker: enough to keep every worker busy while the
#: driver collects a result, few enough that the driver's memory does not grow with
#: the number of images.
IN_FLIGHT_PER_WORKER = 2
#: How often (s) the driver stops waiting for a task to look for a stop request.
WAKE_S = 0.2

Render = Callable[[str, int, int, Any], dict[str, Any]]


def ray_or_none() -> Any:
    """The ``ray`` module, or None where it is not installed."""
    try:
        import ray
    except ImportError:
        return None
    return ray


@contextmanager
def _private_ray(ray: Any, workers: int) -> Iterator[None]:
    """A local Ray of ``workers`` CPUs for the block (one already running is used as it
    is), the SIGTERM handler it replaced put back."""
    if ray.is_initialized():
        yield
        return
    handler = signal.getsignal(signal.SIGTERM)
    try:
        ray.init(
            address="local", num_cpus=workers, include_dashboard=False, log_to_driver=False,
            logging_level=logging.ERROR,
        )  # fmt: skip
    finally:
        _restore_sigterm(handler)
    try:
        yield
    finally:
        ray.shutdown()


def _restore_sigterm(handler: Any) -> None:
    if handler is not None:
        try:
            signal.signal(signal.SIGTERM, handler)
        except ValueError:  # not the main thread: Ray set none either
            pass


def on_ray(
    ray: Any,
    render: Render,
    out_dir: Path,
    seed: int,
    indices: range,
    rig: Any,
    workers: int,
    on_image: Callable[[], None],
) -> list[dict[str, Any]]:
    """``render(out_dir, seed, i, rig)`` for each of ``indices`` as Ray tasks on
    ``workers`` CPUs, at most ``IN_FLIGHT_PER_WORKER * workers`` submitted at a time;
    the results in the order of ``indices``. ``on_image`` is called after each."""
    with _private_ray(ray, workers), _Stops() as stops:
        task = ray.remote(num_cpus=1)(render)
        rig_ref = ray.put(rig)
        todo = iter(indices)
        pending: dict[Any, int] = {}
        results: dict[int, dict[str, Any]] = {}
        limit = IN_FLIGHT_PER_WORKER * workers
        while True:
            for i in todo:
                pending[task.remote(str(out_dir), seed, i, rig_ref)] = i
                if len(pending) >= limit:
                    break
            if not pending:
                return [results[i] for i in indices]
            ready: list[Any] = []
            while not ready:
                stops.check()
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=WAKE_S)
            results[pending.pop(ready[0])] = _result(ray, ready[0])
            on_image()


class _Stops:
    """Inside the block, SIGINT and SIGTERM are only noted; :meth:`check` puts the
    handlers that were in place back and hands a noted signal to its own (which raises
    the stop), or, where that is the default action, signals the process again."""

    def __init__(self) -> None:
        self.noted: int | None = None
        self.previous: dict[int, Any] = {}

    def __enter__(self) -> _Stops:
        try:
            self.previous = {s: signal.signal(s, self._note) for s in _SIGNALS}
        except ValueError:  # not the main thread: no handler can be set
            self.previous = {}
        return self

    def _note(self, signum: int, frame: Any) -> None:
        self.noted = self.noted or signum

    def _restore(self) -> None:
        for s, handler in self.previous.items():
            signal.signal(s, handler)
        self.previous = {}

    def check(self) -> None:
        if self.noted is None:
            return
        handler = self.previous.get(self.noted)
        self._restore()
        if callable(handler):
            handler(self.noted, None)
        elif handler != signal.SIG_IGN:
            os.kill(os.getpid(), self.noted)

    def __exit__(self, exc_type: object, exc: object, tb: object) -> None:
        if exc_type is None:
            self.check()  # a stop noted during the last wait is not lost
        self._restore()


_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _result(ray: Any, ref: Any) -> dict[str, Any]:
    """A task's result; a softarm error raised in the task is raised here as itself."""
    try:
        return ray.get(ref)  # type: ignore[no-any-return]
    except ray.exceptions.RayTaskError as exc:
        if isinstance(exc.cause, SoftarmError):
            raise exc.cause from None
        raise
