"""``softarm experiment NAME``: the paper's benchtop experiments (IV-B, IV-C, IV-D) and
the gain-schedule comparison on the simulated arm. Prints the summaries as JSON (floats
rounded to 6 significant digits; the files in --out keep full precision) on stdout, and
nothing else there: progress goes to stderr."""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

from softarm.commands._args import add_quiet, non_negative_int, output_dir, output_file
from softarm.commands._progress import Progress
from softarm.formatting import rounded

NAMES = ("position", "orientation", "hybrid", "schedule")


def add_parser(sub: Any) -> None:
    """Registers the subcommand."""
    p = sub.add_parser(
        "experiment",
        help="reproduce the paper's benchtop experiments on the simulated arm",
        description=__doc__,
    )
    p.add_argument("name", choices=[*NAMES, "all"], help="which experiment")
    p.add_argument("--out", type=output_dir, default="out/experiments", help="output folder")
    p.add_argument("--seed", type=non_negative_int, default=0, help="seed of the simulated arm")
    p.add_argument("--quick", action="store_true", help="fewer targets, shorter runs")
    p.add_argument("--report", type=output_file, help="also write a Markdown report")
    add_quiet(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Runs the experiment(s) and prints the summaries as JSON."""
    from softarm.experiments import run as run_experiment
    from softarm.experiments.report import write_report

    names = NAMES if args.name == "all" else (args.name,)
    results: dict[str, Any] = {}
    with Progress(len(names), "experiments", "experiment", args.quiet) as bar:
        for name in names:
            bar.describe(name)
            start = time.monotonic()
            results.update(run_experiment(name, args.out, seed=args.seed, quick=args.quick))
            # stdout is the JSON alone: the progress notes go to stderr.
            bar.line(f"{name}: done in {time.monotonic() - start:.1f} s", stderr=True)
            bar.advance()
    print(json.dumps(rounded(results), indent=2, default=str))
    if args.report is not None:
        try:
            figures = str(args.out.resolve().relative_to(args.report.parent.resolve()))
        except ValueError:
            figures = str(args.out)
        write_report(args.report, results, args.seed, figures)
    return 0
