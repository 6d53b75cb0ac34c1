"""The row's ground plane left out of the sun's depth pass in the small renders (C2's
frames, C1's windows around the marker body: those with the small shadow map,
:mod:`softarm.sim.render.shadow_map`).

The ground lies below everything drawn and the sun is above the horizon, so it casts no
shadow on anything; where it alone is in the map its own pixels are lit either way. But
MuJoCo's polygon offset moves the ground's depth in the map a few millimetres towards
the sun, and that darkens sunlit surfaces within millimetres of the ground (the mulch's
top, the foot of a post or a stone): without it they are lit. Whole C1 frames see the
row's foot (on row 90270 in the sun 4,834 pixels of C1's left eye differed, by up to 20
levels) and the cane fit reads them, so they keep the ground in the map; in the small
renders no pixel differed (tests, BENCHMARKS.md "The daylight row"), and the depth pass
no longer fills the whole map with the ground.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softarm.checks import FloatArray

__all__ = [
    "CATEGORY_DECOR",
    "GROUND_MIN_HALF",
    "ground_casters",
    "ground_height",
    "leave_out_of_depth_pass",
]

#: MuJoCo's ``mjCAT_DECOR`` scene category: a geom of it casts no shadow (``mjr_render``
#: leaves it out of the light's depth pass), and is drawn as any other in the others.
CATEGORY_DECOR = 4
#: A plane is the ground when it faces up from the world body and reaches at least this
#: far (m) each way (0: MuJoCo's infinite plane): far beyond what a render culls.
GROUND_MIN_HALF = 10.0


def ground_casters(planes: np.ndarray, sun_travel: FloatArray | None) -> frozenset[int]:
    """The geoms (the ``planes``' ids) to leave out of the sun's depth pass: all of them
    when the sun, travelling along ``sun_travel`` (None: no sun), is above the horizon,
    else none."""
    if sun_travel is None or sun_travel[2] >= 0.0:
        return frozenset()
    return frozenset(int(g) for g in planes)


def ground_height(model: Any, planes: np.ndarray) -> float | None:
    """The height (m) of the lowest of ``model``'s ``planes`` that is the ground (see
    GROUND_MIN_HALF); None without one. Seen from above it (the cameras are), nothing
    below it shows."""
    heights = [
        float(model.geom_pos[g, 2])
        for g in planes
        if model.geom_bodyid[g] == 0
        and np.allclose(model.geom_quat[g], (1.0, 0.0, 0.0, 0.0))
        and all(h <= 0.0 or h >= GROUND_MIN_HALF for h in model.geom_size[g, :2])
    ]
    return min(heights) if heights else None


def leave_out_of_depth_pass(scene: Any, geoms: frozenset[int], mj: Any) -> None:
    """Put the MuJoCo ``scene``'s geoms whose ids are in ``geoms`` in the decor category
    (no shadow cast) until the scene is updated again."""
    left, geom = set(geoms), int(mj.mjtObj.mjOBJ_GEOM)
    for i in range(scene.ngeom):  # the ground is among the first (its id is 0)
        g = scene.geoms[i]
        if g.objtype == geom and g.objid in left:
            g.category = CATEGORY_DECOR
            left.discard(g.objid)
            if not left:
                break
