"""The run's header record (:mod:`softarm.harvest.records.header`) and its ROS 2 bag, for the
commands that run a harvest (``harvest``, ``demo``): the header opens the log and the
report; the bag (``--bag``) is written from the log's records once the run ends."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

__all__ = [
    "check_bag",
    "hardware_header",
    "sim_header",
    "start_log",
    "write_log_bag",
    "write_run_bag",
]


def check_bag(path: Path | None) -> None:
    """Before any work: a ``--bag`` path must be a .mcap file name and the ``ros`` extra
    installed (a one-line error naming the extra)."""
    if path is not None:
        from softarm.viz.bag import check_bag_path

        check_bag_path(path)


def _invocation(args: argparse.Namespace | None, command: str) -> dict[str, Any]:
    """The command, its arguments as typed (``softarm.cli.main`` keeps them in
    ``args.argv``) and as parsed."""
    options = {} if args is None else {k: v for k, v in vars(args).items() if k != "argv"}
    argv = sys.argv[1:] if args is None else getattr(args, "argv", sys.argv[1:])
    return {"command": options.get("command", command), "argv": argv, "options": options}


def sim_header(
    rig: Any, rig_options: Any, args: argparse.Namespace | None = None, command: str = "harvest"
) -> dict[str, Any]:
    """The header of a simulated run: the invocation and the rig's settings."""
    from softarm.harvest.records.header import header_record
    from softarm.harvest.rigs.sim.header import sim_settings

    return header_record(**_invocation(args, command), **sim_settings(rig, rig_options))


def hardware_header(config: Any, args: argparse.Namespace) -> dict[str, Any]:
    """The header of a hardware run on ``config`` (from ``args.config``)."""
    from softarm.harvest.records.header import hardware_settings, header_record

    return header_record(**_invocation(args, "harvest"), **hardware_settings(config, args.config))


def start_log(log: Any, header: Mapping[str, Any]) -> None:
    """Open the run's log (a ``HarvestLog``) with its header record."""
    from softarm.harvest.records.header import HEADER

    log.event(HEADER, **header)


def write_run_bag(records: list[Any], path: Path | None, frames: str | Path | None = None) -> None:
    """Write the run's records to the MCAP bag ``path`` (nothing when None), with the
    camera frames recorded in the folder ``frames`` (``--record-frames``) when given."""
    if path is None:
        return
    from softarm.viz.bag import write_bag

    summary = write_bag(records, path, frames)
    images = sum(n for topic, n in summary.counts.items() if topic.endswith("/compressed"))
    with_images = f", {images} images" if frames is not None else ""
    print(f"bag: {path} ({summary.messages} messages on {len(summary.counts)} topics{with_images})")


def write_log_bag(
    log: Path, path: Path | None, frames: Path | None = None, run: int | None = None
) -> None:
    """Write the records of the run log ``log`` to the MCAP bag ``path`` (nothing when
    None), with the frames recorded in ``frames``; a malformed record is an InputError
    naming the file and the record. A log that ``--log`` appended to holds several runs:
    ``run`` (1 = the first) picks one, and is needed then."""
    if path is None:
        return
    from softarm.errors import InputError

    try:
        write_run_bag(_one_run(log, run), path, frames)
    except InputError as exc:
        raise type(exc)(f"{log}: {exc}") from None


def _one_run(log: Path, run: int | None) -> list[Any]:
    """The records of run ``run`` of ``log`` (None: its only run)."""
    from softarm.errors import InputError
    from softarm.harvest.records.header import split_runs
    from softarm.harvest.records.log import read_log

    runs = split_runs(list(read_log(log)))
    if run is None and len(runs) > 1:
        raise InputError(
            f"the log holds {len(runs)} runs (--log appends); choose one with --run 1..{len(runs)}"
        )
    if run is not None and not 1 <= run <= len(runs):
        raise InputError(f"--run {run}: the log holds {len(runs)} run(s)")
    return runs[0 if run is None else run - 1]
