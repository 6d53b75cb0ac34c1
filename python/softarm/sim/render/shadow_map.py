"""A small shadow map for a small render, texel for texel the full one where it matters.

MuJoCo draws the sun's shadow map anew for every render: the scene's depth seen from
the sun into a square map of ``shadowsize`` texels spanning ``±shadowclip * extent``
metres about the light's axis (``mjr_render``). For the row that is a 2048² map over
the whole scene, and for a C2 frame or a C1 window around the cube (a few hundred
pixels a side) filling and sampling it costs most of the render on a software
rasteriser, while the render sees a small part of the scene.

A small render therefore gets a smaller map (:data:`LOCAL_SIZE` texels a side) at the
same texel pitch, its centre moved to what the render can see: a directional light's
position only places its shadow map (its light comes from its direction alone), so
the light is moved across the sunlight by whole texels of the full map. The small
map's texels are then the full map's texels, each holding the same depth, and every
surface in the render that lies inside it is lit or shaded as in the full map. It is
used only when everything the render can see (every geom in its frustum but the
ground plane) lies inside it; else the full map is drawn.

The ground plane is not counted: it reaches the horizon. Ground that the render sees
outside the small map is drawn lit (as MuJoCo draws ground outside the full map);
the tests measure how much of a render that is (none of the cube or the fruit).

The light's frame is MuJoCo's (``mjr_orthoVec`` and ``mjr_lookAt``): forward the
light's direction f, up u0 = f × (-1, 0, 0) normalised (f × (0, 1, 0) when that is
short), side s = f × u0, up u = s × f. MuJoCo's map spans ``size - 2`` texels (its
border ring stays empty), so its texel pitch is ``2 * clip / (size - 2)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray

__all__ = [
    "BACKDROP_RADIUS",
    "LOCAL_MAX_PIXELS",
    "LOCAL_SIZE",
    "RIM_TEXELS",
    "LightFrame",
    "SunShadows",
    "local_clip",
    "local_light_position",
]

#: The small map's side (texels): at the row's 1.9 mm pitch it spans ±0.97 m.
LOCAL_SIZE = 1024
#: Renders of at most this many pixels use the small map (C2, C1's window): a full C1
#: frame sees the whole row, which the small map cannot hold.
LOCAL_MAX_PIXELS = 640 * 480
#: Geoms whose bounding sphere is larger than this (m) are the backdrop (the hedge's
#: slab, the next row, the mulch, the wires): the small map is not made to hold them.
BACKDROP_RADIUS = 0.3
#: Texels left free on each side of what the render sees (the map's rim, and
#: MuJoCo's 2 x 2 filtering of the shadow test).
RIM_TEXELS = 4


@dataclass(frozen=True)
class LightFrame:
    """The sun's shadow-map frame as MuJoCo builds it from ``direction``: ``side`` and
    ``up`` (unit vectors across the sunlight), the full map's texel ``pitch`` (m) and
    its half-span ``clip`` (m) about the light's axis."""

    side: FloatArray
    up: FloatArray
    pitch: float
    clip: float

    @classmethod
    def of(cls, direction: FloatArray, clip: float, size: int) -> LightFrame:
        """The frame of a light along ``direction`` whose map spans ±``clip`` m with
        ``size`` texels a side."""
        f = np.asarray(direction, float) / np.linalg.norm(direction)
        u0 = np.cross(f, [-1.0, 0.0, 0.0])
        if u0 @ u0 <= 0.01:
            u0 = np.cross(f, [0.0, 1.0, 0.0])
        u0 /= np.linalg.norm(u0)
        s = np.cross(f, u0)
        s /= np.linalg.norm(s)
        u = np.cross(s, f)
        return cls(s, u / np.linalg.norm(u), 2.0 * clip / (size - 2), clip)


def local_clip(frame: LightFrame, size: int = LOCAL_SIZE) -> float:
    """The half-span (m) of a ``size``-texel map at ``frame``'s pitch."""
    return 0.5 * frame.pitch * (size - 2)


def local_light_position(
    frame: LightFrame,
    light: FloatArray,
    centres: FloatArray,
    radii: FloatArray,
    size: int = LOCAL_SIZE,
) -> FloatArray | None:
    """Where to put the light (now at ``light``) so that a ``size``-texel map at
    ``frame``'s pitch holds every sphere (``centres`` (N, 3), ``radii`` (N,), world
    frame) with RIM_TEXELS to spare, its texels on the full map's: ``light`` moved
    across the sunlight by whole texels. None when the spheres do not fit."""
    axes = np.vstack([frame.side, frame.up])
    offset = (np.asarray(centres, float) - light) @ axes.T  # (N, 2) across the light
    r = np.asarray(radii, float)[:, None]
    # What lies wholly outside the full map is drawn lit with either map.
    inside = (np.abs(offset) - r < frame.clip).all(axis=1)
    offset, r = offset[inside], r[inside]
    if len(offset) == 0:
        return np.asarray(light, float).copy()
    low, high = (offset - r).min(axis=0), (offset + r).max(axis=0)
    half = local_clip(frame, size) - RIM_TEXELS * frame.pitch
    if np.any(high - low > 2.0 * half):
        return None
    # The full and the small map's texel edges coincide when the centres differ by
    # whole texels ((size - full size) / 2 texels is whole: both sides are even).
    steps = np.round(0.5 * (low + high) / frame.pitch)
    shifted: FloatArray = light + (steps * frame.pitch) @ axes
    return shifted


class SunShadows:
    """The row's sun in a compiled ``model`` (its light named ``sun``): the full shadow
    map's frame, the settings of a small map's context, and where the light goes for a
    render that can use one (:func:`local_light_position`)."""

    def __init__(self, model: Any, mujoco: Any) -> None:
        self.light = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_LIGHT, "sun")
        self.size = int(model.vis.quality.shadowsize)
        clip = float(model.stat.extent) * float(model.vis.map.shadowclip)
        self.frame = LightFrame.of(model.light_dir[self.light], clip, self.size)
        #: A small map's ``vis.map.shadowclip`` (MuJoCo multiplies it by the extent).
        self.local_shadowclip = local_clip(self.frame) / float(model.stat.extent)

    def place(self, data: Any, centres: FloatArray, radii: FloatArray) -> bool:
        """Move the light in ``data`` (after ``mj_camlight``) so that a small map holds
        the spheres a render can see; False (the light left alone) when they do not
        fit, and the render needs the full map."""
        moved = local_light_position(self.frame, data.light_xpos[self.light], centres, radii)
        if moved is None:
            return False
        data.light_xpos[self.light] = moved
        return True

    def in_map(self, data: Any, centres: FloatArray, radii: FloatArray) -> npt.NDArray[np.bool_]:
        """Which spheres (world ``centres`` (N, 3), ``radii``) reach into the small map
        about the light as :meth:`place` put it in ``data``: a caster wholly outside it
        draws nothing into it."""
        frame = self.frame
        axes = np.vstack([frame.side, frame.up])
        offset = (centres - data.light_xpos[self.light]) @ axes.T
        reach = local_clip(frame) + np.asarray(radii, float)[:, None]
        result: npt.NDArray[np.bool_] = (np.abs(offset) < reach).all(axis=1)
        return result
