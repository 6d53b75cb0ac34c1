"""Rendered bushes for the perception tests; a machine without MuJoCo or an offscreen
OpenGL skips these tests with the renderer's own reason, or fails them where the render
is required (tests/render_required.py)."""

from __future__ import annotations

import os

import softarm
from render_required import rendering
from softarm.sim.bush import Bush

os.environ.setdefault("MUJOCO_GL", "egl")


def rendered_world(seed: int, n_berries: int = 10, c2_scale: float = 1.0):  # type: ignore[no-untyped-def]
    """The rendered world of a fresh bush of ``seed`` seen by the simulated rig's cameras
    (C2's image scaled by ``c2_scale``), or a skip when this machine cannot render (a
    failure where the render is required)."""
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.render.world import world_for
    from softarm.sim.rig_cameras import BASE_TAG_ID

    cams = default_cameras()
    bush = Bush.generate(
        softarm.SoftArm.blackberry(), n_berries, seed, view_point=cams.T_base_c1[:3, 3],
        unripe_fraction=0.4,
    )  # fmt: skip
    with rendering():
        world = world_for(bush, cams, BASE_TAG_ID, c2_scale=c2_scale)
        world.c1_left()
    return world
