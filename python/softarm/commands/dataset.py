"""``softarm dataset``: labelled images of random rendered bushes (COCO boxes and masks,
ripeness, depth, intrinsics) for training a detector; on Ray when the sweep extra is
installed."""

from __future__ import annotations

import argparse
import time
from typing import TYPE_CHECKING

from softarm.commands._args import add_quiet, float_range, int_range, output_dir, positive_int
from softarm.commands._looks import LOOKS
from softarm.commands._worlds import world_metavar, world_type
from softarm.errors import ParameterError
from softarm.sim.world import WorldName
from softarm.stops import stops_on_signals

if TYPE_CHECKING:
    from softarm.sim.render.dataset import DatasetRig

#: Most cores a local Ray is asked for.
MAX_WORKERS = 1024


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``dataset`` subcommand."""
    p = sub.add_parser(
        "dataset",
        help="render labelled images of random bushes (COCO boxes, masks, ripeness, depth)",
        description="Each image is one random rendered bush seen by C1 (left or right eye) or "
        "C2, written to OUT/images, its depth (16-bit PNG, mm) to OUT/depth, its instance map "
        "to OUT/instances and every berry and cane to OUT/annotations.json (COCO). Runs on Ray "
        "across the cores when the sweep extra is installed, else one image after the other. "
        "Needs MuJoCo with an offscreen OpenGL (MUJOCO_GL=egl). The set is written into a "
        "fresh folder beside OUT and moved into place when complete: a stop (exit 130/143) "
        "or a failure leaves OUT as it was. Then 8-bit previews of the depth and instance "
        "maps, for an image viewer, go to OUT/preview. See docs/dataset.md.",
    )
    p.add_argument(
        "--out", type=output_dir, required=True,
        help="output folder: new, empty, or an earlier dataset (it holds annotations.json), "
        "which the new set replaces whole once complete; any other folder is refused",
    )  # fmt: skip
    p.add_argument("--images", type=positive_int, required=True, help="how many images")
    p.add_argument("--seed", type=int_range(0, 2**63 - 1), default=0, help="dataset seed")
    p.add_argument("--workers", type=int_range(1, MAX_WORKERS), help="cores used (default: all)")
    p.add_argument(
        "--scale", type=float_range(0.0, 1.0), default=1.0,
        help="image size and focal length factor (1: C1 1280x720, C2 640x480)",
    )  # fmt: skip
    p.add_argument(
        "--world", type=world_type(WorldName.BUSH, WorldName.ROW),
        metavar=world_metavar(WorldName.BUSH, WorldName.ROW), default=WorldName.BUSH,
        help="'bush' (default): the rendered bush; 'row': the bush in a hedgerow in daylight, "
        "every frame through a camera model, fruit green, red, turning and ripe "
        "(docs/perception.md, 'The daylight row')",
    )  # fmt: skip
    p.add_argument(
        "--look", choices=LOOKS, default=None,
        help="--world row: the daylight family (default random: one of the four per image)",
    )  # fmt: skip
    add_quiet(p)
    p.set_defaults(run=run)


def default_rig(
    scale: float = 1.0, world: WorldName = WorldName.BUSH, look: str = "random"
) -> DatasetRig:
    """The simulated harvest's cameras and markers, images scaled by ``scale``; the
    ``world`` and its ``look`` (the row's)."""
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.render.dataset import DatasetRig
    from softarm.sim.rig_cameras import BASE_TAG_ID

    c = default_cameras(scale=scale)
    return DatasetRig(
        c.T_base_c1, c.model(1), c.model(2), c.T_ee_c2, c.T_ee_cube, c.T_base_tag,
        BASE_TAG_ID, c.base_tag, world, look,
    )  # fmt: skip


@stops_on_signals  # a stop removes the unfinished set and shuts Ray down
def run(args: argparse.Namespace) -> int:
    """Exit 0 once every image and annotations.json are written."""
    from softarm.commands._progress import Progress
    from softarm.sim.render.dataset import ray_workers, write_dataset
    from softarm.sim.render.gl_check import require_offscreen_gl
    from softarm.sim.render.preview import write_previews

    require_offscreen_gl()  # one line naming the fix, before OUT is created
    if args.look is not None and args.world is not WorldName.ROW:
        raise ParameterError("--look: for the rendered row (--world row)")
    rig = default_rig(args.scale, args.world, args.look or "random")
    workers = ray_workers(args.images, args.workers)
    start = time.perf_counter()
    with Progress(args.images, "dataset", "image", args.quiet) as progress:
        coco = write_dataset(
            args.out, args.images, args.seed, rig, workers=args.workers, on_image=progress.advance
        )
    write_previews(args.out)  # 8-bit PNGs of depth/ and instances/ a viewer shows
    counts = {c["id"]: 0 for c in coco["categories"]}
    for annotation in coco["annotations"]:
        counts[annotation["category_id"]] += 1
    named = ", ".join(f"{counts[c['id']]} {c['name']}" for c in coco["categories"])
    where = f"on Ray ({workers} cores)" if workers else "in one process"
    print(
        f"dataset: {len(coco['images'])} images, {named} in "
        f"{time.perf_counter() - start:.1f} s {where} -> {args.out / 'annotations.json'}"
    )
    return 0
