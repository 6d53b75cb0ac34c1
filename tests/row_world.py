"""A small sunlit row (row seed 4, 6 berries, an arm reaching for the first) for the
renderer's tests; skips where MuJoCo or an OpenGL context is missing."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import softarm
from softarm.sim.bush import Bush


def sunlit_row_world() -> Any:
    """A row world in the sun look with the harvest's cameras (C2 at half scale,
    320 x 240), the arm at 0.9 of the first berry's q. The caller closes it."""
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.render import RenderUnavailableError
    from softarm.sim.render.row_look import RowLook
    from softarm.sim.render.world import arm_sections, world_for
    from softarm.sim.rig_cameras import BASE_TAG_ID

    pytest.importorskip("mujoco")
    cams = default_cameras()
    arm = softarm.SoftArm.blackberry()
    bush = Bush.generate(arm, 6, 4, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.4)
    try:
        world = world_for(bush, cams, BASE_TAG_ID, RowLook.named("sun", 4), 0.5)
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))
    q = np.asarray(bush.berries[0].q) * 0.9
    world.set_arm(arm_sections(arm, q), arm.forward(q))
    return world


def stepped_casters(centres, heights, radii, travel, drop, ground, view):  # type: ignore[no-untyped-def]
    """The shadow casters' sweep as it was before softarm.sim.render.shadow_casters:
    spheres 0.25 m apart along 3 m of sunlight, each grown by 0.125 m, the ground not
    counted (the reference its tests and benchmark compare with)."""
    from softarm.sim.render.culling import in_frustum

    kept = np.zeros(len(radii), bool)
    for t in np.arange(0.125, 3.0, 0.25):
        kept |= in_frustum(centres + t * travel, radii + 0.125, *view)
    return kept
