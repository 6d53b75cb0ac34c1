"""``softarm replay``: turn a harvest run log into a rerun recording (the ``viz`` extra)."""

from __future__ import annotations

import argparse

from softarm.commands._args import config_file, output_file


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``replay`` subcommand."""
    p = sub.add_parser(
        "replay",
        help="turn a harvest run log (--log run.jsonl) into a rerun recording",
        description="Replay the JSON-lines log of `softarm harvest --log run.jsonl` in rerun: "
        "the state machine, the commanded arm (drawn on the nominal model), the measured "
        "end-effector pose, the berry estimates and the errors on the run's own time. "
        "Without --record the rerun viewer is started. Needs the viz extra: "
        "pip install 'softarm[viz]'. Exit status 0, or 2 for a bad log or a missing extra.",
    )
    p.add_argument("log", type=config_file, help="run log written by `softarm harvest --log`")
    p.add_argument("--record", type=output_file, metavar="OUT.rrd", help="save the recording")
    p.add_argument(
        "--view",
        action="store_true",
        help="also start the rerun viewer (the default without --record)",
    )
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Write the recording; returns 0."""
    from softarm.viz.replay import replay

    n = replay(args.log, args.record, spawn=args.view or args.record is None)
    where = f"recording: {args.record}" if args.record is not None else "sent to the viewer"
    print(f"{n} records of {args.log}; {where}")
    return 0
