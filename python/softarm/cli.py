"""The ``softarm`` command line. Each subcommand lives in ``softarm.commands.<name>`` as a
module with ``add_parser(subparsers)`` and ``run(args) -> int``; a module imports its heavy
dependencies inside ``run``, so that ``softarm --help`` stays fast and a missing optional
dependency only affects its own command.

Every parser is a :class:`softarm.commands._args.Parser`: help shows the defaults, and a
usage error is one line naming the option, exit status 2. A :class:`SoftarmError` raised
by a command is one line too (exit 2), and so is a stop by SIGINT/SIGTERM (exit 130/143).
``python -m softarm`` runs the same entry point."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

import softarm
from softarm.commands._args import Parser
from softarm.errors import SoftarmError
from softarm.stops import Interrupted

#: Subcommand name -> module implementing it.
COMMANDS: dict[str, str] = {
    "demo": "softarm.commands.demo",
    "harvest": "softarm.commands.harvest",
    "experiment": "softarm.commands.experiment",
    "plan": "softarm.commands.plan",
    "bench": "softarm.commands.bench",
    "config": "softarm.commands.config",
    "completion": "softarm.commands.completion",
    "sweep": "softarm.commands.sweep",
    "tune": "softarm.commands.tune",
    "calibrate": "softarm.commands.calibrate",
    "identify": "softarm.commands.identify",
    "replay": "softarm.commands.replay",
    "dataset": "softarm.commands.dataset",
    "camera": "softarm.commands.camera",
    "detect": "softarm.commands.detect",
    "detector": "softarm.commands.detector",
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand registered."""
    parser = Parser(
        prog="softarm",
        description="Soft robotic harvesting arm: kinematics, control, planning, vision.",
    )
    parser.add_argument("--version", action="version", version=f"softarm {softarm.__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _UNAVAILABLE.clear()
    for name, module in COMMANDS.items():
        try:
            importlib.import_module(module).add_parser(sub)
        except ImportError as exc:
            _unavailable(sub, name, exc)
    return parser


def _unavailable(sub: argparse._SubParsersAction[Parser], name: str, exc: ImportError) -> None:
    """A command whose module cannot be imported (a missing optional dependency) is
    listed and says why when run; the other commands keep working."""
    reason = f"unavailable: {exc}"
    sub.add_parser(name, help=f"({reason})", description=reason)
    _UNAVAILABLE[name] = reason


#: Commands whose module failed to import -> why, filled by :func:`build_parser`.
_UNAVAILABLE: dict[str, str] = {}


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``softarm`` script; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    if argv and argv[0] in _UNAVAILABLE:  # before parsing: its options are unknown
        print(f"softarm {argv[0]}: {_UNAVAILABLE[argv[0]]}", file=sys.stderr)
        return 2
    args = parser.parse_args(argv)
    args.argv = argv  # as typed, for the header record of a run (softarm.harvest.records.header)
    try:
        return int(args.run(args))
    except SoftarmError as exc:
        print(f"softarm {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except (Interrupted, KeyboardInterrupt) as exc:
        # A command that owns hardware handles the signal itself (vent, log); this is the
        # tidy exit for the others.
        status = exc.exit_status if isinstance(exc, Interrupted) else 130
        print(f"softarm {args.command}: {str(exc) or 'interrupted by SIGINT'}", file=sys.stderr)
        return status


if __name__ == "__main__":
    sys.exit(main())
