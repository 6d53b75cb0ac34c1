"""Per-period render costs of the rendered bush (``softarm harvest --sim --world bush``):
C1's window around the marker cube and C2's 320 x 240 frame, with the arm 3 % short of
a berry, 4 poses on each bush (310-312 unless ``--seeds``), each rendered 10 times; the
medians in ms.

It measures the softarm tree first on PYTHONPATH, so that an older tree can be measured
beside this one (``git worktree add DIR COMMIT``, copy the built ``_core.abi3.so`` into
``DIR/python/softarm``, run with ``PYTHONPATH=DIR/python``)::

    MUJOCO_GL=egl python examples/bench_bush_render.py
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import numpy as np

import softarm
from softarm.harvest.rigs.sim.options import default_cameras
from softarm.harvest.rigs.sim.worlds import C2_SCALE
from softarm.sim.bush import Bush
from softarm.sim.render.world import arm_sections, world_for
from softarm.sim.rig_cameras import BASE_TAG_ID
from softarm.vision.poses import invert

REPEATS = 10


def _cube_window(world: Any, T_base_cube: np.ndarray) -> Callable[[], object]:
    """The harvest's window around the cube (a tree from before ``cube_window``
    rendered a fixed 256-pixel one around the cube's centre)."""
    if hasattr(world, "cube_window"):
        return lambda: world.cube_window(T_base_cube)
    p = invert(world.stereo.T_base_left) @ T_base_cube[:, 3]
    u, v = world.stereo.left.project(p[None, :3])[0]
    return lambda: world.c1_left_window((float(u), float(v)))


def _median_ms(render: Callable[[], object]) -> float:
    render()  # its renderer made
    start = time.perf_counter()
    for _ in range(REPEATS):
        render()
    return 1e3 * (time.perf_counter() - start) / REPEATS


def main(argv: list[str] | None = None) -> None:
    """Print the tree measured and the two medians."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--seeds", type=int, nargs="+", default=[310, 311, 312], help="bushes (310 311 312)"
    )
    args = parser.parse_args(argv)
    print(softarm.__file__)
    arm = softarm.SoftArm.blackberry()
    cams = default_cameras()
    window, c2 = [], []
    for seed in args.seeds:
        bush = Bush.generate(arm, 10, seed, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.4)
        world = world_for(bush, cams, BASE_TAG_ID, c2_scale=C2_SCALE)
        for berry in bush.berries[:4]:
            q = np.asarray(berry.q) * 0.97
            T_base_ee = arm.forward(q)
            world.set_arm(arm_sections(arm, q), T_base_ee)
            window.append(_median_ms(_cube_window(world, T_base_ee @ cams.T_ee_cube)))
            c2.append(_median_ms(world.c2_frame))
        world.close()
    print(
        f"cube window median {np.median(window):.1f} ms, "
        f"C2 frame median {np.median(c2):.1f} ms ({len(window)} poses)"
    )


if __name__ == "__main__":
    main()
