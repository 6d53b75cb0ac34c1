"""Headroom in a render: MuJoCo's 8-bit output clips at 255, so in the row's sun the
white paper of the marker body (albedo 1, lit by the sun and the sky together) is cut
at the render, before any camera model sees it: a camera that meters on the marker
could then only scale a step already clipped, and the edge refinement's gradient
centroid is biased by a clipped step (docs/perception.md, "Cube tracking in the row").

C1's window around the marker is therefore drawn with the scene's lights dimmed
(:func:`dimmed`) to the share :func:`window_share` gives: just enough that a white tag
facing any way the body's tags face stays under the render's full scale, by the
lights' own terms (each directional light's diffuse by the cosine to it, plus every
ambient; shadows left out, so it errs towards dimming), with :data:`MARGIN` to spare;
1 (no dimming) where no tag can reach full scale (in shade, against the light, under
cloud). The camera model (:meth:`~softarm.sim.render.camera_effects.CameraEffects.
roi_exposure_of`) scales its exposure back: radiance up to 255 / share DN reaches the
simulated sensor, where the exposure decides what clips, as in a camera. The cost is
the render's quantisation, one DN of the dimmed render being 1 / share DN of the
scene's, which is why the share is no smaller than the tags need.

MuJoCo draws the skybox unlit, so it is not dimmed: sky in a dimmed window comes out
1 / share times as bright, relative to the lit scene, as in a full frame (no window of
the diagnosis poses held sky).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.errors import ParameterError

__all__ = ["MARGIN", "dimmed", "window_share"]

#: The brightest white's radiance is taken this much higher than the lights' terms
#: give it (what the sum leaves out: MuJoCo's shading and texture filtering).
MARGIN = 1.1


def window_share(model: Any, normals: FloatArray) -> float:
    """The share of its lights' strength the MuJoCo ``model`` is drawn with for C1's
    marker window (see the module docstring): 1 / (MARGIN x the radiance, in the
    render's full scale, of a white surface facing the brightest of ``normals`` (N, 3),
    unit vectors in the world frame), at most 1. The model's lights are taken as
    directional, fixed in the world (the row's sun and sky are)."""
    toward = -np.asarray(model.light_dir, np.float64)
    toward /= np.linalg.norm(toward, axis=1, keepdims=True)
    ambient = np.asarray(model.vis.headlight.ambient) + model.light_ambient.sum(axis=0)
    lit = np.clip(np.asarray(normals) @ toward.T, 0.0, None) @ model.light_diffuse + ambient
    return float(min(1.0, 1.0 / (MARGIN * float(lit.max()))))


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
