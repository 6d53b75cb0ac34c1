"""The optional rerun SDK (the ``viz`` extra): imported only when a view or a recording is
asked for, with a one-line error that says how to install it."""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

from softarm.errors import SoftarmError

__all__ = [
    "INSTALL",
    "MissingDependencyError",
    "close_recording",
    "open_recording",
    "require_rerun",
]

INSTALL = "pip install 'softarm[viz]' (or pip install rerun-sdk)"

#: Name of the recordings' application in the viewer.
APPLICATION = "softarm"

#: The one timeline every entity is logged on: the harvest's own (simulated) clock.
TIMELINE = "sim_time"


class MissingDependencyError(SoftarmError, ImportError):
    """An optional dependency is not installed."""


def require_rerun() -> Any:
    """The ``rerun`` module, or :class:`MissingDependencyError` naming the extra."""
    try:
        return importlib.import_module("rerun")
    except ImportError as exc:
        raise MissingDependencyError(
            f"the rerun view needs rerun-sdk, the optional extra 'viz' ({exc.name} "
            f"missing): {INSTALL}"
        ) from None


def open_recording(name: str, record: str | Path | None = None, spawn: bool = False) -> Any:
    """A ``rerun.RecordingStream`` named ``name`` that writes to the file ``record``
    (``.rrd``), streams to a spawned viewer (``spawn``), or both.

    Its own stream, not rerun's global one, so that two recordings in one process (tests,
    a replay beside a live run) never mix. Nothing goes to the network except the local
    viewer that ``spawn`` starts.
    """
    if record is None and not spawn:
        raise SoftarmError("open_recording: give a file to record to or spawn=True")
    rr = require_rerun()
    stream = rr.RecordingStream(APPLICATION, recording_id=name)
    if spawn:
        # Start the viewer without connecting, then send to it and to the file at once.
        stream.spawn(connect=False)
        sinks = [rr.GrpcSink()]
        if record is not None:
            sinks.append(rr.FileSink(str(record)))
        stream.set_sinks(*sinks)
    else:
        stream.save(str(record))
    stream.send_recording_name(name)
    return stream


def close_recording(stream: Any) -> None:
    """Flush ``stream`` and close its sinks: an ``.rrd`` file gets its footer (the index
    readers use) and is complete."""
    stream.flush()
    stream.disconnect()
