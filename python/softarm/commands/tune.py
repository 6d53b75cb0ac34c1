"""``softarm tune``: search the resolver's gains with Ray Tune over a sweep spec's plants."""

from __future__ import annotations

import argparse
from pathlib import Path

from softarm.commands._args import add_quiet, output_file


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``tune`` subcommand."""
    p = sub.add_parser(
        "tune",
        help="tune the resolver's gains on Ray Tune over a sweep spec's plants and seeds",
        description="Optuna's TPE (via Ray Tune) searches the closed-loop gains ([tune.space] "
        "of SPEC, or a default space); every candidate harvests each (plant point, seed) of "
        "SPEC. The best (most harvested, then shortest cycle) is written as a [gains] file, "
        "loadable by `softarm harvest --gains`. Never tune on the seeds you report. "
        "Needs the sweep extra: pip install 'softarm[sweep]'.",
    )
    p.add_argument("spec", type=Path, help="sweep spec (TOML: [sweep], [sweep.plant], [tune])")
    p.add_argument("--out", type=output_file, required=True, help="gains file to write (TOML)")
    p.add_argument("--samples", type=int, help="candidates to try (default: [tune] samples)")
    p.add_argument("--address", help="join this Ray cluster (default: start Ray on this machine)")
    p.add_argument("--cpus", type=int, help="cores of the local Ray (default: all)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_quiet(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Exit 0 with the gains written, 2 on a bad spec."""
    from softarm.errors import ConfigError
    from softarm.sweep import load_spec
    from softarm.sweep._deps import require
    from softarm.sweep.tune import run_tune

    spec = load_spec(args.spec)
    for module in ("ray.tune", "optuna", "pyarrow", "tqdm"):  # the sweep extra, up front
        require(module)
    if args.cpus is not None and args.cpus < 1:
        raise ConfigError(f"--cpus: must be >= 1, got {args.cpus}")
    outcome = run_tune(
        spec, args.out, address=args.address, cpus=args.cpus, samples=args.samples,
        progress=not (args.no_progress or args.quiet),
    )  # fmt: skip
    keys = [k for k in outcome.candidates[0] if k not in ("score", "success", "cycle_s",
                                                          "mean_error_mm")]  # fmt: skip
    shown = 1 if args.quiet else 5  # --quiet: the best alone
    print("best candidates (score = harvested fraction - 1e-4 x mean s / berry):")
    print("  " + "  ".join(f"{k:>12}" for k in [*keys, "harvested", "s/berry", "score"]))
    for c in outcome.candidates[:shown]:
        vals = [f"{c[k]:12.4g}" if isinstance(c[k], float) else f"{c[k]!s:>12}" for k in keys]
        vals += [f"{100 * c['success']:11.1f}%", f"{c['cycle_s']:12.2f}", f"{c['score']:12.4f}"]
        print("  " + "  ".join(vals))
    print(f"gains: {args.out}")
    return 0
