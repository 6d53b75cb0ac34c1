"""``softarm sweep SPEC`` when SPEC is a perception map (a ``[perception]`` table,
:mod:`.perception_spec`): the map run on Ray where it is installed (else in this
process), then its table and picture written in ``--out``."""

from __future__ import annotations

import argparse
import shutil
import sys
from typing import Any

from softarm.formatting import plural

__all__ = ["run_perception_map"]


def run_perception_map(args: argparse.Namespace, data: dict[str, Any]) -> int:
    """Exit 0 when every trial ran, 1 if some failed, 2 on a bad spec (raised as
    ConfigError), 128 + the signal if interrupted."""
    from softarm.errors import ConfigError
    from softarm.sweep.perception_map import run_map, summarise, write_outputs
    from softarm.sweep.perception_spec import parse_perception_spec

    spec = parse_perception_spec(data, str(args.spec))
    if args.gains is not None:
        raise ConfigError("--gains: a perception map has no controller (no [sweep] spec)")
    if args.cpus is not None and args.cpus < 1:
        raise ConfigError(f"--cpus: must be >= 1, got {args.cpus}")
    trials = spec.trials()
    if not args.quiet:
        cells, seeds = len(spec.cells()), len(spec.seeds)
        print(
            f"perception map: {plural(len(trials), 'trial')} ({plural(cells, 'cell')} x "
            f"{plural(seeds, 'seed')}) -> {args.out}",
            flush=True,
        )

    def progress(row: dict[str, Any]) -> None:
        if not (args.quiet or args.no_progress):
            cell = "/".join(str(row[k]) for k in ("look", "effects", "lookalikes", "fruit"))
            state = "failed: " + row["error"] if row.get("error") else f"{row.get('wall_s')} s"
            print(f"  {cell} seed {row['seed']}: {state}", file=sys.stderr, flush=True)

    outcome = run_map(
        spec, args.out, address=args.address, cpus=args.cpus, resume=args.resume, on_trial=progress
    )
    args.out.mkdir(parents=True, exist_ok=True)
    if args.spec.resolve() != (args.out / "spec.toml").resolve():
        shutil.copyfile(args.spec, args.out / "spec.toml")  # what the map was made from
    paths = write_outputs(summarise(spec, args.out), args.out)
    where = f"on Ray ({outcome.cpus:g} CPUs)" if outcome.on_ray else "in this process"
    print(
        f"{plural(outcome.ran, 'trial')} run {where} ({outcome.failed} failed), "
        f"{outcome.skipped} already done, {outcome.wall_s:.0f} s; "
        f"{', '.join(str(p) for p in paths)}",
        flush=True,
    )
    if outcome.interrupted:
        again = f"softarm sweep {args.spec} --out {args.out} --resume"
        print(
            f"interrupted: finished trials are in {args.out}/cells; complete the map with "
            f"`{again}`",
            file=sys.stderr,
        )
        return 128 + int(outcome.signal or 2)
    if outcome.failed:
        print(
            "some trials failed (their rows in cells/ say why); --resume runs them again",
            file=sys.stderr,
        )
        return 1
    return 0
