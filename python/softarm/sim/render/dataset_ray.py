"""The dataset's images rendered as Ray tasks on a private local Ray
(:func:`softarm.sim.render.dataset.write_dataset` uses it when Ray is installed).

Two things a plain ``ray.wait`` loop gets wrong:

* Submission is bounded: at most :data:`IN_FLIGHT_PER_WORKER` tasks per worker are
  submitted at a time, the next one as each finishes. Submitting every task up front
  makes the driver hold a task record per image (``--images 1000000`` grew it by about
  60 MB/s).
* Signals. ``ray.init`` installs SIGTERM handlers that call ``sys.exit`` (and the
  C++ core worker a failure handler that dumps a stack and aborts: exit 134), and Ray
  runs Python's handlers from inside its C++ calls, where an exception comes out as a
  ``SystemError``. So while Ray starts and while the tasks run, SIGINT and SIGTERM are
  only noted (:class:`_Stops`; Ray's own SIGTERM handlers are not installed, nor the
  C++ failure handler: ``RAY_DISABLE_FAILURE_SIGNAL_HANDLER``), ``ray.wait`` wakes
  every :data:`WAKE_S`, and a noted stop is handed to the handler that was in place
  (``softarm dataset``'s raises :class:`~softarm.stops.Interrupted`)
  between two calls into Ray: it unwinds through ``ray.shutdown``.
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
    # Read when Ray is imported: no C++ failure handler takes SIGTERM (see above).
    os.environ.setdefault("RAY_DISABLE_FAILURE_SIGNAL_HANDLER", "1")
    try:
        import ray
    except ImportError:
        return None
    return ray


@contextmanager
def _private_ray(ray: Any, workers: int) -> Iterator[None]:
    """A local Ray of ``workers`` CPUs for the block (one already running is used as it
    is); a stop while it starts is raised once it has started, and shuts it down."""
    if ray.is_initialized():
        yield
        return
    try:
        with _Stops(), _without_ray_sigterm_handlers(ray):
            ray.init(
                address="local", num_cpus=workers, include_dashboard=False,
                log_to_driver=False, logging_level=logging.ERROR,
            )  # fmt: skip
        yield
    finally:
        if ray.is_initialized():
            ray.shutdown()


@contextmanager
def _without_ray_sigterm_handlers(ray: Any) -> Iterator[None]:
    """Inside the block Ray installs no SIGTERM handler of its own (``ray.init`` sets one
    that calls ``sys.exit`` through ``ray._private.utils.set_sigterm_handler``): the
    handler in place stays, and ``ray.shutdown`` stops Ray's processes."""
    utils: Any = getattr(getattr(ray, "_private", None), "utils", None)
    original = getattr(utils, "set_sigterm_handler", None)
    if original is None:  # another Ray: its handler is replaced by _Stops' restore
        yield
        return
    utils.set_sigterm_handler = lambda handler: None
    try:
        yield
    finally:
        utils.set_sigterm_handler = original


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
