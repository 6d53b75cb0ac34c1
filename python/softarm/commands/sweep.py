"""``softarm sweep``: the simulated harvest over a grid of plants × seeds, on Ray."""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from softarm.commands._args import add_quiet
from softarm.formatting import plural


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``sweep`` subcommand."""
    p = sub.add_parser(
        "sweep",
        help="run the simulated harvest over plants x seeds on Ray (results.parquet, summary.png)",
        description="Every (plant point, seed) of SPEC is one Ray task harvesting one simulated "
        "bush. Results stream to OUT/results.parquet (one row per berry); OUT/summary.png and "
        "OUT/summary.md summarise them. Needs the sweep extra: pip install 'softarm[sweep]'.",
    )
    p.add_argument(
        "spec",
        type=Path,
        help="sweep spec (TOML: [sweep], [sweep.plant]; or [perception]: the row's "
        "perception map, docs/robustness.md)",
    )
    p.add_argument("--out", type=Path, required=True, help="results directory")
    p.add_argument("--address", help="join this Ray cluster (default: start Ray on this machine)")
    p.add_argument("--cpus", type=int, help="cores of the local Ray (default: all)")
    p.add_argument("--resume", action="store_true", help="complete the table in --out")
    p.add_argument("--gains", type=Path, help="resolver gains file ([gains], e.g. from tune)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_quiet(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Exit 0 when every trial ran, 1 if some failed, 2 on a bad spec, 130 if interrupted."""
    from softarm.errors import ConfigError
    from softarm.files import load_toml
    from softarm.sweep import load_gains, load_spec
    from softarm.sweep._deps import require
    from softarm.sweep.runner import run_sweep
    from softarm.sweep.summary import markdown_summary, plot_summary

    data = load_toml(args.spec, "sweep spec")
    if "perception" in data:  # the row's perception map: a spec kind of its own
        from softarm.sweep.perception_cli import run_perception_map

        return run_perception_map(args, data)
    spec = load_spec(args.spec)
    for module in ("ray", "pyarrow", "tqdm"):  # the sweep extra, before anything starts
        require(module)
    if args.gains is not None:
        spec = spec.with_gains(load_gains(args.gains))
    if args.cpus is not None and args.cpus < 1:
        raise ConfigError(f"--cpus: must be >= 1, got {args.cpus}")
    trials = spec.trials()
    if not args.quiet:
        points, seeds = len(spec.plant_points()), len(spec.seeds)
        grid = f"{plural(points, 'plant point')} x {plural(seeds, 'seed')}"
        print(
            f"sweep: {plural(len(trials), 'trial')} ({grid}), "
            f"{plural(len(trials) * spec.berries, 'berry')} -> {args.out}",
            flush=True,
        )
    outcome = run_sweep(
        spec, args.out, address=args.address, resume=args.resume, cpus=args.cpus,
        progress=not (args.no_progress or args.quiet),
    )  # fmt: skip
    args.out.mkdir(parents=True, exist_ok=True)
    if args.spec.resolve() != (args.out / "spec.toml").resolve():
        shutil.copyfile(args.spec, args.out / "spec.toml")  # what the table was made from

    import pyarrow.parquet as pq

    rows = pq.read_table(outcome.table).to_pylist() if outcome.table.exists() else []
    if rows:
        (args.out / "summary.md").write_text(markdown_summary(rows, spec.swept_keys))
        plot_summary(rows, spec.swept_keys, args.out / "summary.png")
    rate = ""
    if outcome.berries:
        rate = f", {outcome.berries_per_hour:.0f} berries/h on {outcome.cpus:g} CPUs"
    print(
        f"{plural(outcome.ran, 'trial')} run ({outcome.failed} failed), "
        f"{outcome.skipped} already done"
        f"{rate}; table {outcome.table}",
        flush=True,
    )
    if outcome.interrupted:
        again = f"softarm sweep {args.spec} --out {args.out} --resume"
        print(f"interrupted: finished trials are in the table; complete it with `{again}`",
              file=sys.stderr)  # fmt: skip
        return 128 + int(outcome.signal or 2)  # 130 for SIGINT, 143 for SIGTERM
    if any(r["error"] is not None for r in rows):
        print("some trials failed (see the error column); --resume runs them again",
              file=sys.stderr)  # fmt: skip
        return 1
    return 0
