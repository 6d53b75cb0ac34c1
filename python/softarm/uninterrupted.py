"""Sections a stop must not cut in half: freeing an OpenGL context, for one. A SIGTERM
raised half-way through ``eglDestroyContext`` leaves a context neither alive nor freed;
the next close, or its finalizer at exit, then fails (``EGL_BAD_CONTEXT``) and the
traceback replaces the stop.

:func:`uninterrupted` marks such a section; the command's signal handler
(:mod:`softarm.stops`) asks :func:`defer` first, and a stop that arrives
inside is raised when the section ends. A leaf: any layer may use it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["defer", "uninterrupted"]

_depth = 0
_deferred: list[Callable[[], None]] = []


@contextmanager
def uninterrupted() -> Iterator[None]:
    """Inside the block a stop is held back; it is raised when the (outermost) block
    ends, after the block's own work is complete."""
    global _depth
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        if _depth == 0 and _deferred:
            stop = _deferred[0]
            _deferred.clear()
            stop()


def defer(stop: Callable[[], None]) -> bool:
    """Hold ``stop`` (a function that raises it) until the current section ends; False
    outside any section (the caller raises it now)."""
    if _depth == 0:
        return False
    _deferred.append(stop)
    return True
