"""The optional rerun SDK (the ``viz`` extra): imported only when a view or a recording is
asked for, with a one-line error that says how to install it."""

from __future__ import annotations

import importlib
import logging
import os
import shutil
import sys
from pathlib import Path
from typing import Any

from softarm.errors import MissingDependencyError, SoftarmError

__all__ = [
    "INSTALL",
    "ViewerUnavailableError",
    "close_recording",
    "open_recording",
    "require_rerun",
]

INSTALL = "pip install 'softarm[viz]' (or pip install rerun-sdk)"

#: Name of the recordings' application in the viewer.
APPLICATION = "softarm"

#: The longest wait (s) for a viewer to take the last data when the run ends.
VIEWER_FLUSH_S = 10.0

#: The one timeline every entity is logged on: the harvest's own (simulated) clock.
TIMELINE = "sim_time"


class ViewerUnavailableError(SoftarmError):
    """The rerun viewer cannot be started here (no display, no viewer executable)."""


def require_rerun() -> Any:
    """The ``rerun`` module, or :class:`MissingDependencyError` naming the extra."""
    try:
        return importlib.import_module("rerun")
    except ImportError as exc:
        raise MissingDependencyError(
            f"the rerun view needs rerun-sdk, the optional extra 'viz' ({exc.name} "
            f"missing): {INSTALL}",
            "viz",
        ) from None


def open_recording(
    name: str, record: str | Path | None = None, spawn: bool = False, blueprint: Any = None
) -> Any:
    """A ``rerun.RecordingStream`` named ``name`` that writes to the file ``record``
    (``.rrd``), streams to a spawned viewer (``spawn``), or both; ``blueprint`` is the
    viewer's default layout (:mod:`softarm.viz.layout`).

    Its own stream, not rerun's global one, so that two recordings in one process (tests,
    a replay beside a live run) never mix. Nothing goes to the network except the local
    viewer that ``spawn`` starts.
    """
    if record is None and not spawn:
        raise SoftarmError("open_recording: give a file to record to or spawn=True")
    rr = require_rerun()
    if record is not None:  # outputs create their folders
        Path(record).parent.mkdir(parents=True, exist_ok=True)
    stream = rr.RecordingStream(APPLICATION, recording_id=name)
    if spawn:
        _spawn_viewer(rr, stream)
        # The viewer started without a connection: send to it and to the file at once.
        sinks = [rr.GrpcSink()]
        if record is not None:
            sinks.append(rr.FileSink(str(record)))
        stream.set_sinks(*sinks)
    else:
        stream.save(str(record))
    stream.send_recording_name(name)
    if blueprint is not None:  # the viewer's default layout, saved in the file too
        stream.send_blueprint(blueprint)
    return stream


def close_recording(stream: Any, viewer: bool = False) -> None:
    """Flush ``stream`` and close its sinks: an ``.rrd`` file gets its footer (the index
    readers use) and is complete.

    With a ``viewer`` (spawned), a viewer closed by the user before the end makes the
    flush fail: that is logged as a warning and the rest (a file beside it) still
    closes, since a run must not fail for a closed window; the wait is bounded so that
    an unresponsive viewer cannot hang the command.
    """
    try:
        stream.flush(timeout_sec=VIEWER_FLUSH_S if viewer else 1e38)
    except RuntimeError as exc:
        if not viewer:
            raise SoftarmError(
                f"the recording could not be completed: {_first_line(exc)}"
            ) from None
        logging.getLogger(__name__).warning("the rerun viewer went away: %s", _first_line(exc))
    stream.disconnect()


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else repr(exc)


def _spawn_viewer(rr: Any, stream: Any) -> None:
    """Start the rerun viewer (the executable the rerun-sdk wheel installs beside this
    Python, when it is not on PATH), or a one-line :class:`ViewerUnavailableError`.

    Without a display the viewer starts and dies at once and the run would lose its
    data, so that case is refused before the run starts.
    """
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        raise ViewerUnavailableError(
            "no display for the rerun viewer (DISPLAY and WAYLAND_DISPLAY are unset): "
            "record to a file with --record run.rrd and open it with `rerun run.rrd`"
        )
    beside = Path(sys.executable).with_name("rerun")
    exe = shutil.which("rerun") or (str(beside) if beside.exists() else None)
    if exe is None:
        raise ViewerUnavailableError(
            f"the rerun viewer executable is not on PATH: {INSTALL}, or use --record run.rrd"
        )
    try:
        rr.spawn(connect=False, executable_path=exe, recording=stream)
    except (RuntimeError, OSError) as exc:
        raise ViewerUnavailableError(f"cannot start the rerun viewer: {_first_line(exc)}") from None
