"""``softarm experiment NAME``: the paper's benchtop experiments (IV-B, IV-C, IV-D) and
the gain-schedule comparison on the simulated arm."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def add_parser(sub: Any) -> None:
    """Registers the subcommand."""
    p = sub.add_parser(
        "experiment",
        help="reproduce the paper's benchtop experiments on the simulated arm",
        description=__doc__,
    )
    p.add_argument("name", choices=["position", "orientation", "hybrid", "schedule", "all"])
    p.add_argument("--out", type=Path, default=Path("experiments-out"), help="output folder")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--quick", action="store_true", help="fewer targets, shorter runs")
    p.add_argument("--report", type=Path, default=None, help="also write a Markdown report")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Runs the experiment(s) and prints the summaries as JSON."""
    from softarm.experiments import run as run_experiment
    from softarm.experiments.report import write_report

    results = run_experiment(args.name, args.out, seed=args.seed, quick=args.quick)
    print(json.dumps(results, indent=2, default=str))
    if args.report is not None:
        try:
            figures = str(args.out.resolve().relative_to(args.report.parent.resolve()))
        except ValueError:
            figures = str(args.out)
        write_report(args.report, results, args.seed, figures)
    return 0
