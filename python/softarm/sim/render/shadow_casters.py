"""Which geoms out of a small render's picture are drawn for their shadow alone.

A geom outside the frustum may still shade what the render sees: its shadow falls
along the sunlight. A geom is kept when its bounding sphere, swept along the sunlight,
may meet the frustum (:func:`~softarm.sim.render.culling.swept_in_frustum`: the sweep
is a capsule, wholly outside a side plane of the frustum when both its ends are). The
sweep is followed SHADOW_REACH m, or until the sphere lies wholly below the ground
plane: the cameras are above the ground and it reaches the horizon, so nothing below it
shows, and the sunlight goes only further down.

Before, the sweep was taken as spheres 0.25 m apart, each grown by 0.125 m to cover it:
every geom within 12 cm of the frustum was kept whatever the sun's direction. The
capsule keeps a fifth to two fifths fewer casters in C1's windows and C2's frames
(each kept caster's triangles are transformed in every colour pass by the software
rasteriser), and the pictures are the same pixel for pixel (tests).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.sim.render.culling import swept_in_frustum

__all__ = ["GROUND_MARGIN", "SHADOW_REACH", "SWEEP_PIECES", "shadow_casters"]

#: How far (m) a geom's shadow is followed along the sunlight.
SHADOW_REACH = 3.0
#: The sweep is tested in this many pieces.
SWEEP_PIECES = 8
#: The sweep ends when the sphere's top is this far (m) below the ground: the plane's
#: own depth in the shadow map is moved by MuJoCo's polygon offset, millimetres.
GROUND_MARGIN = 0.01


def shadow_casters(
    centres: FloatArray,
    heights: FloatArray,
    radii: FloatArray,
    travel: FloatArray,
    drop: float,
    ground: float | None,
    view: tuple[tuple[int, int], float, tuple[float, float]],
) -> npt.NDArray[np.bool_]:
    """Which spheres (``centres`` (N, 3) in MuJoCo's camera frame, world ``heights``
    (N,) of those centres, ``radii`` (N,)) may shade the picture ``view`` = (size,
    focal, principal) of :func:`~softarm.sim.render.culling.in_frustum` when swept
    along the sunlight: ``travel`` the sunlight's unit direction in the camera frame,
    ``drop`` its world z component (negative: the sun above the horizon); ``ground``
    the ground plane's height (m), None without one."""
    reach = np.full(len(radii), SHADOW_REACH)
    if ground is not None and drop < 0.0:
        # Where the sphere's top passes GROUND_MARGIN below the ground.
        under = (heights + radii - ground + GROUND_MARGIN) / -drop
        reach = np.clip(under, 0.0, SHADOW_REACH)
    size, focal, principal = view
    kept = np.zeros(len(radii), bool)
    # In pieces: a whole sweep passing a corner of the frustum is outside no one plane.
    for k in range(SWEEP_PIECES):
        starts = centres + (k / SWEEP_PIECES) * reach[:, None] * travel
        ends = centres + ((k + 1) / SWEEP_PIECES) * reach[:, None] * travel
        kept |= swept_in_frustum(starts, ends, radii, size, focal, principal)
    return kept
