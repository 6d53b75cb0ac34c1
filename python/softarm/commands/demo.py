"""``softarm demo``: a simulated harvest of a few berries, with plots, and no hardware."""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``demo`` subcommand."""
    p = sub.add_parser(
        "demo",
        help="simulated harvest of a few berries with plots (no hardware)",
        description="Simulated bush, arm and cameras; the full vision → resolver → plant "
        "loop harvests a few berries. Writes plots, the report and the log into --out.",
    )
    p.add_argument("--out", type=Path, default=Path("out"), help="output folder")
    p.add_argument("--berries", type=int, default=5, help="berries (default 5)")
    p.add_argument("--seed", type=int, default=0, help="seed of the bush and the arm")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Harvest, print a line per berry and the summary, save the figures."""
    import matplotlib

    matplotlib.use("Agg")
    from softarm.commands.harvest import _line, _summary
    from softarm.harvest.plots import plot_run
    from softarm.harvest.sim_rig import SimRigOptions, build_sim_rig

    # Vents are logged by the safety layer (softarm.hardware.safety): show them tidily.
    logging.basicConfig(level=logging.WARNING, format="  [%(name)s] %(message)s")
    args.out.mkdir(parents=True, exist_ok=True)
    log = args.out / "harvest_log.jsonl"
    log.unlink(missing_ok=True)
    print(f"simulated harvest: {args.berries} berries, seed {args.seed}")
    rig = build_sim_rig(SimRigOptions(n_berries=args.berries, seed=args.seed, log_path=log))
    start = time.monotonic()
    report = rig.run(
        lambda i, r: print(_line(i, args.berries, r, time.monotonic() - start), flush=True)
    )
    print(_summary(report.to_dict()))
    report.save(args.out / "harvest_report.json")
    plot_run(rig, report, args.out / "harvest.png")
    for name in ("harvest.png", "harvest_report.json", "harvest_log.jsonl"):
        print(f"saved {args.out / name}")
    return 0
