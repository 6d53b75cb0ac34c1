"""A harvest run log (``softarm harvest --log run.jsonl``) turned into a rerun recording:
whatever the log holds (states, commands drawn on the model arm, measured poses, berry
estimates, errors, faults), on the run's own timeline. See :mod:`softarm.viz.records`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from softarm.errors import InputError
from softarm.harvest.log import read_log
from softarm.viz.layout import harvest_blueprint
from softarm.viz.records import RecordLogger
from softarm.viz.rerun_sdk import close_recording, open_recording, require_rerun

__all__ = ["replay"]


def replay(
    log: str | Path,
    record: str | Path | None = None,
    spawn: bool = False,
    model: Any | None = None,
    grasp_offset: float = 0.03,
) -> int:
    """Log every record of ``log`` to ``record`` (.rrd), a spawned viewer, or both;
    returns the number of records. ``model``: the arm the run controlled (default the
    nominal blackberry arm), on which the commanded elongations are drawn.

    Raises:
        InputError: a line is not JSON or a record is malformed (the message names the
            record's number and the field).
        MissingDependencyError: rerun-sdk (the ``viz`` extra) is not installed.
    """
    require_rerun()  # before reading a large log
    if model is None:
        import softarm

        model = softarm.SoftArm.blackberry()
    path = Path(log)
    stream = open_recording(f"replay {path.name}", record, spawn, harvest_blueprint(False))
    logger = RecordLogger(stream, require_rerun(), model, grasp_offset, berries_from_results=True)
    n = 0
    try:
        for n, rec in enumerate(read_log(path), start=1):
            try:
                logger.log(rec)
            except InputError as exc:
                raise type(exc)(f"{path}: record {n}: {exc}") from None
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: record {n + 1} is not JSON ({exc.msg})") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not UTF-8 text (byte offset {exc.start})") from None
    finally:
        close_recording(stream)
    return n
