"""``softarm replay``: turn a harvest run log into a rerun recording (the ``viz`` extra)."""

from __future__ import annotations

import argparse

from softarm.commands._args import data_file, int_range, non_negative_int, output_file
from softarm.commands.harvest import MAX_BERRIES


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
    p.add_argument("log", type=data_file, help="run log written by `softarm harvest --log`")
    p.add_argument("--record", type=output_file, metavar="OUT.rrd", help="save the recording")
    p.add_argument(
        "--view",
        action="store_true",
        help="also start the rerun viewer (the default without --record)",
    )
    p.add_argument(
        "--sim-seed",
        type=non_negative_int,
        metavar="SEED",
        help="draw the simulated bush of `harvest --sim --seed SEED` (canes, true berries); "
        "checked against the log's berries",
    )
    p.add_argument(
        "--berries",
        type=int_range(1, MAX_BERRIES),
        default=5,
        help="berries of that run's bush (its --berries; with --sim-seed)",
    )
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Write the recording; returns 0."""
    from softarm.viz.replay import replay

    scene = None if args.sim_seed is None else (args.sim_seed, args.berries)
    n = replay(args.log, args.record, spawn=args.view or args.record is None, scene=scene)
    where = f"recording: {args.record}" if args.record is not None else "sent to the viewer"
    print(f"{n} records of {args.log}; {where}")
    return 0
