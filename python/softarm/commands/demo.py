"""``softarm demo``: a simulated harvest of a few berries, with plots, and no hardware."""

from __future__ import annotations

import argparse

from softarm.commands._args import add_quiet, int_range, non_negative_int, output_dir
from softarm.commands._looks import add_look
from softarm.commands._plant import add_plant_options, plant_options
from softarm.commands._worlds import world_metavar, world_type
from softarm.commands.harvest import MAX_BERRIES
from softarm.errors import ParameterError
from softarm.sim.world import WorldName
from softarm.stops import drives_arm

#: What the demo writes into --out.
OUTPUTS = ("harvest.png", "harvest_report.json", "harvest_log.jsonl")


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``demo`` subcommand."""
    p = sub.add_parser(
        "demo",
        help="simulated harvest of a few berries with plots (no hardware)",
        description="Simulated bush, arm and cameras; the full vision → resolver → plant "
        f"loop harvests a few berries. Writes {', '.join(OUTPUTS)} into --out.",
    )
    p.add_argument("--out", type=output_dir, default="out", help="output folder")
    p.add_argument(
        "--berries", type=int_range(1, MAX_BERRIES), default=5, help="berries to harvest"
    )
    p.add_argument("--seed", type=non_negative_int, default=0, help="seed of the bush and arm")
    p.add_argument(
        "--world", type=world_type(*WorldName), metavar=world_metavar(*WorldName),
        default=WorldName.TAGS,
        help="'tags' (default): tagged berries, mapped canes; 'bush': the markerless "
        "harvest in the rendered bush (render extra), with harvest_c1.png, what C1 saw; "
        "'row': the same bush inside a hedgerow in daylight (--look)",
    )  # fmt: skip
    add_look(p)
    add_plant_options(p, sim_only_flag=False)
    add_quiet(p)
    p.set_defaults(run=run)


@drives_arm("demo")
def run(args: argparse.Namespace) -> int:
    """Harvest, print a line per berry and the summary, save the figures."""
    from softarm.commands.harvest import check_render, configure_logging, run_sim

    if args.look is not None and args.world is not WorldName.ROW:
        raise ParameterError("--look: for the rendered row (--world row)")
    options = plant_options(args)  # a bad --plant/--identified fails before any output
    check_render(args.world.rendered)  # so does a missing renderer
    if args.world.rendered:
        from softarm.commands.harvest import BUSH_UNRIPE_FRACTION

        options.update(world=args.world, unripe_fraction=BUSH_UNRIPE_FRACTION)
    if args.world is WorldName.ROW:
        options.update(look=args.look)
    configure_logging(args.quiet)
    args.out.mkdir(parents=True, exist_ok=True)
    log = args.out / "harvest_log.jsonl"
    log.unlink(missing_ok=True)
    report, plot = args.out / "harvest_report.json", args.out / "harvest.png"
    args.log = log  # named in the line a stop prints (drives_arm)
    run_sim(args.berries, args.seed, log, report, plot, args.quiet, **options)
    return 0  # a demo, not a test: a faulted berry is reported, not an error
