"""The rendered bush world: a blackberry bush with leaves, clutter and the arm, drawn by
MuJoCo's offscreen renderer (``MUJOCO_GL=egl``) for the stereo eye-to-hand camera C1 and
the eye-in-hand camera C2, with the ground truth of every frame.

MuJoCo is imported only when a renderer is built; without it, or without an offscreen
OpenGL, :class:`RenderUnavailableError` says how to enable it."""

from softarm.sim.render.labels import KINDS, GeomLabels
from softarm.sim.render.look import BushLook
from softarm.sim.render.renderer import (
    BushRenderer,
    RenderedFrame,
    RenderUnavailableError,
    require_mujoco,
)
from softarm.sim.render.world import ZED2_BASELINE, RenderedBush, arm_sections

__all__ = [
    "KINDS",
    "ZED2_BASELINE",
    "BushLook",
    "BushRenderer",
    "GeomLabels",
    "RenderUnavailableError",
    "RenderedBush",
    "RenderedFrame",
    "arm_sections",
    "require_mujoco",
]
