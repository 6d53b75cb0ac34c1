"""Headroom in a render: MuJoCo's 8-bit output clips at 255, so in the row's sun the
white paper of the marker body (albedo 1, lit by the sun and the sky together) is cut
at the render, before any camera model sees it: a camera that meters on the marker
could then only scale a step already clipped, and the edge refinement's gradient
centroid is biased by a clipped step (docs/perception.md, "Cube tracking in the row").

C1's window around the marker is therefore drawn with the scene's lights at
:data:`WINDOW_HEADROOM` of their strength (:func:`dimmed`), and the camera model
(:meth:`~softarm.sim.render.camera_effects.CameraEffects.roi_exposure_of`) scales its
exposure back: radiance up to 255 / WINDOW_HEADROOM DN reaches the simulated sensor,
where the exposure decides what clips, as in a camera. The cost is the render's
quantisation: one DN of the dimmed render is 1 / WINDOW_HEADROOM DN of the scene's.

MuJoCo draws the skybox unlit, so it is not dimmed: sky in a window comes out
1 / WINDOW_HEADROOM times as bright, relative to the lit scene, as in a full frame.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from softarm.errors import ParameterError

__all__ = ["WINDOW_HEADROOM", "dimmed"]

#: The share of the scene's light C1's marker window is rendered with: the row's
#: brightest lit white (sun up to 1.25 plus ambient and sky fill, about 1.6 of the
#: render's full scale) stays under 255 DN.
WINDOW_HEADROOM = 0.5


@contextmanager
def dimmed(model: Any, share: float) -> Iterator[None]:
    """Within the block, every light of the MuJoCo ``model`` (each light's ambient,
    diffuse and specular, and the headlight's) at ``share`` of its strength; restored
    after, whatever happens inside.

    Raises:
        ParameterError: ``share`` not in (0, 1].
    """
    if not 0 < share <= 1:
        raise ParameterError(f"share must be in (0, 1], got {share}")
    head = model.vis.headlight
    lights = (model.light_ambient, model.light_diffuse, model.light_specular)
    saved = [a.copy() for a in lights]
    saved_head = [head.ambient.copy(), head.diffuse.copy(), head.specular.copy()]
    try:
        for a in lights:
            a *= share
        head.ambient, head.diffuse, head.specular = (v * share for v in saved_head)
        yield
    finally:
        for a, s in zip(lights, saved, strict=True):
            a[:] = s
        head.ambient, head.diffuse, head.specular = saved_head
