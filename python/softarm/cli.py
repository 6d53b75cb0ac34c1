"""The ``softarm`` command line. Each subcommand lives in ``softarm.commands.<name>`` as a
module with ``add_parser(subparsers)`` and ``run(args) -> int``; modules are imported
lazily so that ``softarm --help`` stays fast and a missing optional dependency only
affects its own command."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from softarm.errors import SoftarmError

#: Subcommand name -> module implementing it.
COMMANDS: dict[str, str] = {
    "demo": "softarm.commands.demo",
    "harvest": "softarm.commands.harvest",
    "experiment": "softarm.commands.experiment",
    "plan": "softarm.commands.plan",
    "bench": "softarm.commands.bench",
    "calibrate": "softarm.commands.calibrate",
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand registered."""
    parser = argparse.ArgumentParser(
        prog="softarm",
        description="Soft robotic harvesting arm: kinematics, control, planning, vision.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module in COMMANDS.values():
        importlib.import_module(module).add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``softarm`` script; returns the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.run(args))
    except SoftarmError as exc:
        print(f"softarm {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
