"""``softarm replay``: turn a harvest run log into a rerun recording (the ``viz`` extra)
and/or a ROS 2 bag (``--bag``, the ``ros`` extra)."""

from __future__ import annotations

import argparse
from pathlib import Path

from softarm.commands._args import (
    data_file,
    int_range,
    non_negative_int,
    output_file,
    positive_int,
)
from softarm.commands._run_info import check_bag, write_log_bag
from softarm.commands.harvest import MAX_BERRIES
from softarm.errors import ParameterError
from softarm.formatting import plural
from softarm.stops import stops_on_signals


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``replay`` subcommand."""
    p = sub.add_parser(
        "replay",
        help="turn a harvest run log (--log run.jsonl) into a rerun recording",
        description="Replay the JSON-lines log of `softarm harvest --log run.jsonl` in rerun: "
        "the state machine, the commanded arm (drawn on the nominal model), the measured "
        "end-effector pose, the berry estimates and the errors on the run's own time. "
        "Without --record or --bag the rerun viewer is started. Needs the viz extra: "
        "pip install 'softarm[viz]'; --bag alone needs only the ros extra: "
        "pip install 'softarm[ros]'. The log's header record gives the arm, the bush and "
        "the cameras. Exit status 0, 2 for a bad log or a missing extra, 130/143 stopped "
        "by SIGINT/SIGTERM (no half-written bag is left).",
    )
    p.add_argument("log", type=data_file, help="run log written by `softarm harvest --log`")
    p.add_argument("--record", type=output_file, metavar="OUT.rrd", help="save the recording")
    p.add_argument(
        "--bag", type=output_file, metavar="RUN.mcap",
        help="write the log as a ROS 2 bag (rosbag2, MCAP; ros extra; docs/ros.md)",
    )  # fmt: skip
    p.add_argument(
        "--frames", type=Path, metavar="DIR",
        help="with --bag: add the camera frames recorded in DIR (`harvest --sim --world bush "
        "--record-frames DIR`) as CompressedImage topics (docs/ros.md)",
    )  # fmt: skip
    p.add_argument(
        "--run", type=positive_int, metavar="N", dest="run_number",
        help="with --bag: the run to write from a log that --log appended to more than "
        "once (1 = the first); needed when the log holds more than one run",
    )  # fmt: skip
    p.add_argument(
        "--foxglove", nargs="?", const="127.0.0.1:8765", metavar="HOST:PORT",
        help="serve the log to Foxglove on HOST:PORT at the run's own pace, from the moment "
        "a client subscribes (alone: 127.0.0.1:8765; foxglove extra; docs/ros.md)",
    )  # fmt: skip
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
        "checked against the log's berries (for a log without a header record)",
    )
    p.add_argument(
        "--berries",
        type=int_range(1, MAX_BERRIES),
        default=5,
        help="berries of that run's bush (its --berries; with --sim-seed)",
    )
    p.set_defaults(run=run)


@stops_on_signals  # a stop removes the half-written bag and its temporary folder
def run(args: argparse.Namespace) -> int:
    """Write the bag and/or the recording, or serve the log to Foxglove; returns 0."""
    if args.foxglove is not None:
        from softarm.viz.foxglove_live import serve_log

        n = serve_log(args.log, args.foxglove)
        print(f"{plural(n, 'record')} of {args.log} served to Foxglove")
        return 0
    check_bag(args.bag)
    if args.frames is not None and args.bag is None:
        raise ParameterError("--frames: adds the recorded frames to a bag; give --bag too")
    if args.run_number is not None and args.bag is None:
        raise ParameterError("--run: picks the run a bag is written from; give --bag too")
    if args.bag is not None and not args.view and args.record is None:
        write_log_bag(args.log, args.bag, args.frames, args.run_number)
        return 0
    from softarm.viz.replay import replay
    from softarm.viz.rerun_sdk import require_rerun

    require_rerun()  # before the bag is written
    write_log_bag(args.log, args.bag, args.frames, args.run_number)
    scene = None if args.sim_seed is None else (args.sim_seed, args.berries)
    n = replay(args.log, args.record, spawn=args.view or args.record is None, scene=scene)
    where = f"recording: {args.record}" if args.record is not None else "sent to the viewer"
    print(f"{plural(n, 'record')} of {args.log}; {where}")
    return 0
