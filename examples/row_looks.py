"""Pictures of the daylight row (``--world row``), one per look, and what it costs to
render: C1's left eye on the same bush and seed in each look (``sun``, ``overcast``,
``backlight``, ``dusk``), as delivered (the camera model applied), written as
``row_<look>.png`` (scaled down to ``--width``); then the milliseconds per C1 frame
(the pinhole render, and the whole delivered frame) of the row with and without
shadows and of the rendered bush, the medians of ``--repeats`` renders, into
``row_render_cost.json``.

The pictures in docs/img and the figures in docs/perception.md come from::

    MUJOCO_GL=egl python examples/row_looks.py --out docs/img --cost-out docs/data
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import cv2

import softarm
from softarm.harvest.rigs.sim.options import default_cameras
from softarm.sim.bush import Bush
from softarm.sim.render.row_look import FAMILIES, RowLook
from softarm.sim.render.world import RenderedBush
from softarm.sim.rig_cameras import BASE_TAG_ID


def _world(bush: Bush, cams: Any, look: RowLook | None, shadows: bool = True) -> RenderedBush:
    return RenderedBush(
        bush, cams.T_base_c1, cams.model(1), cams.model(2), cams.T_ee_c2, cams.T_ee_cube,
        cams.T_base_tag, BASE_TAG_ID, cams.base_tag, cams.cube_marker, look, shadows=shadows,
    )  # fmt: skip


def _median_ms(render: Callable[[], object], repeats: int) -> float:
    render()  # its renderer made
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        render()
        times.append(time.perf_counter() - start)
    return round(1e3 * statistics.median(times), 1)


def _cost(bush: Bush, cams: Any, seed: int, repeats: int) -> dict[str, Any]:
    """ms per C1 left frame: the row with and without shadows, and the bush."""
    out: dict[str, Any] = {"repeats": repeats, "image": list(cams.model(1).image_size)}
    for name, look, shadows in (
        ("row_shadows", RowLook.named("sun", seed), True),
        ("row_no_shadows", RowLook.named("sun", seed), False),
        ("bush", None, True),
    ):
        world = _world(bush, cams, look, shadows)

        def pinhole(w: RenderedBush = world) -> object:
            return w.renderer.render("c1_left")

        def delivered(w: RenderedBush = world) -> object:
            return w.c1_left()

        try:
            out[name] = {
                "geoms": int(world.renderer.model.ngeom),
                "pinhole_ms": _median_ms(pinhole, repeats),
                "delivered_ms": _median_ms(delivered, repeats),
            }
        finally:
            world.close()
        print(name, out[name], flush=True)
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument("--out", type=Path, default=Path("out/row_looks"), help="pictures")
    parser.add_argument(
        "--cost-out", type=Path, default=Path("out/row_looks"), help="row_render_cost.json"
    )
    parser.add_argument("--seed", type=int, default=21, help="bush and look seed")
    parser.add_argument("--repeats", type=int, default=5, help="renders per cost figure")
    parser.add_argument("--no-cost", action="store_true", help="pictures only")
    parser.add_argument(
        "--width", type=int, default=640, help="pictures scaled down to this width (px)"
    )
    args = parser.parse_args(argv)
    cams = default_cameras()
    bush = Bush.generate(
        softarm.SoftArm.blackberry(), 8, args.seed, view_point=cams.T_base_c1[:3, 3],
        unripe_fraction=0.3,
    )  # fmt: skip
    args.out.mkdir(parents=True, exist_ok=True)
    for name in FAMILIES:
        world = _world(bush, cams, RowLook.named(name, args.seed))
        try:
            path = args.out / f"row_{name}.png"
            image: Any = world.c1_left().colour
            if args.width < image.shape[1]:  # the docs' copy: smaller files
                height = round(image.shape[0] * args.width / image.shape[1])
                image = cv2.resize(image, (args.width, height), interpolation=cv2.INTER_AREA)
            cv2.imwrite(str(path), image)
            print(f"{name}: {path}", flush=True)
        finally:
            world.close()
    if not args.no_cost:
        cost = _cost(bush, cams, args.seed, args.repeats)
        args.cost_out.mkdir(parents=True, exist_ok=True)
        path = args.cost_out / "row_render_cost.json"
        path.write_text(json.dumps(cost, indent=1) + "\n")
        print(f"cost: {path}")


if __name__ == "__main__":
    main()
