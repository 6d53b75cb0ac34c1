"""C1's marker window drawn as the arm over a static scene kept from an earlier render.

C1 is fixed (eye-to-hand), and between control periods of a harvest only the arm and
the marker body it carries move; the row (leaves, canes, fruit, ground, sky) changes
only when a leaf is pushed aside or a berry picked, a few times a harvest (row seed 4:
once in 219 windows in the sun, 8 times in 253 overcast). So C1's left eye without the
arm is drawn once, whole, colour and depth from the same render (the sun's shadows
included), and kept while the scene's state is the same (:meth:`StaticScene.layer`:
every geom's place, size and group but the arm's, and the lights' strength, which the
window's headroom dims). Each window then draws the arm alone, with the geoms that may
shade it (:func:`arm_casters`), and takes a pixel from that render where it lies
nearer than the kept scene's (:func:`composite`): the arm over the row, hidden where
the row lies in front of it.

What differs from the window drawn whole: the arm's shadow on the row (the kept scene
has no arm), and the pixels where the kept frame's full shadow map and the window's
small one differ (:mod:`softarm.sim.render.shadow_map`: single pixels on shadow edges).
The arm's own shading, its shadows on itself, and the row's shadows on it come from
the window's own render, texel for texel as before. A window reaching past the frame
is drawn whole (:meth:`CompositedWindows.render` returns None).

Off by default (``RenderedBush(composited_windows=...)``): the arm's render keeps most of
a window's fixed cost (the clears, the sun's depth pass, the read-back, the culling),
about 25 ms of CPU against 40 for the whole window, and the kept row, 170 ms a whole
frame, is drawn again at every leaf pushed or berry picked (12 times in the harvest of
diagnosis row 90260, overcast), so a harvest's CPU per simulated second came out the
same (BENCHMARKS.md, "The daylight row").
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.sim.render.ground_shadow import leave_out_of_depth_pass
from softarm.sim.render.labels import KINDS
from softarm.sim.render.last_render import scene_state
from softarm.sim.render.window_camera import geom_bounds, window_camera

__all__ = [
    "DEPTH_TOLERANCE",
    "SHARE_STEPS",
    "CompositedWindows",
    "StaticScene",
    "arm_casters",
    "composite",
    "quantised_share",
]

#: The arm's pixel is taken where it lies at least this much (m) nearer than the kept
#: scene's: the same surface drawn through two projections (the whole frame's and the
#: window's moved principal point) comes out at depths a float's rounding apart.
DEPTH_TOLERANCE = 1e-3
#: The window's light share (softarm.sim.render.headroom) is rounded down to a step of
#: 1 / SHARE_STEPS, so that the scene kept at one share serves the windows of nearby
#: marker poses (down: the window stays at least as dimmed as its tags need).
SHARE_STEPS = 32
#: Kept scenes (one per state and share; a whole C1 frame, 7 bytes a pixel).
KEPT = 4
#: Where the arm's pixels come from: MuJoCo's pixel (CULLED_GROUP hides a geom).
CULLED_GROUP = 5

Layer = tuple[npt.NDArray[np.uint8], npt.NDArray[np.float32]]


def quantised_share(share: float) -> float:
    """``share`` rounded down to a step of 1 / SHARE_STEPS (1 stays 1)."""
    return float(np.floor(share * SHARE_STEPS + 1e-9)) / SHARE_STEPS


def arm_casters(
    centres: FloatArray,
    radii: FloatArray,
    arm_centres: FloatArray,
    arm_radii: FloatArray,
    travel: FloatArray,
) -> npt.NDArray[np.bool_]:
    """Which geoms (bounding spheres ``centres`` (N, 3), ``radii`` (N,)) may shade the arm
    (spheres ``arm_centres`` (M, 3), ``arm_radii`` (M,)) in sunlight travelling along
    ``travel`` (unit): those whose sphere meets the ray from an arm sphere's centre
    towards the sun, a cylinder of the two radii summed (the shadow of a sphere on a
    sphere lies within it)."""
    v = centres[:, None, :] - arm_centres[None, :, :]  # (N, M, 3)
    t = np.maximum(-(v @ travel), 0.0)  # how far towards the sun the nearest point lies
    closest = v + t[..., None] * travel
    reach = radii[:, None] + arm_radii[None, :]
    hit: npt.NDArray[np.bool_] = (np.einsum("nmk,nmk->nm", closest, closest) <= reach**2).any(
        axis=1
    )
    return hit


def composite(
    scene: Layer, arm: Layer, tolerance: float = DEPTH_TOLERANCE
) -> npt.NDArray[np.uint8]:
    """The colour of ``scene`` (colour, depth in m) with ``arm``'s pixels where the arm's
    render lies nearer by more than ``tolerance`` (nothing drawn: depth at the far
    plane, never nearer)."""
    nearer = arm[1] < scene[1] - tolerance
    out = scene[0].copy()
    out[nearer] = arm[0][nearer]
    return out


def _read(renderer: Any, r: Any) -> Layer:
    """Colour (H, W, 3) RGB and depth (H, W) m of the scene MuJoCo renderer ``r`` was last
    given, from one ``mjr_render`` (the ground out of the sun's depth pass where the
    renderer's small renders leave it out)."""
    mj, m = renderer._mj, renderer.model
    if renderer._no_shadow:
        leave_out_of_depth_pass(r._scene, renderer._no_shadow, mj)
    if r._gl_context:
        r._gl_context.make_current()
    h, w = r._height, r._width
    colour, raw = np.empty((h, w, 3), np.uint8), np.empty((h, w), np.float32)
    mj.mjr_render(r._rect, r._scene, r._mjr_context)
    mj.mjr_readPixels(colour, raw, r._rect, r._mjr_context)
    # MuJoCo's reversed depth (mujoco.Renderer's own conversion, perspective cameras).
    near = np.float32(m.vis.map.znear * m.stat.extent)
    far = np.float32(m.vis.map.zfar * m.stat.extent)
    c = np.float32(-0.5) * (-(far + near) / (far - near)) - np.float32(0.5)
    d = np.float32(-0.5) * (-(np.float32(2) * far * near) / (far - near))
    depth = (d / (raw.astype(np.float64) + c)).astype(np.float32)
    return np.ascontiguousarray(colour[::-1]), np.ascontiguousarray(depth[::-1])


class StaticScene:
    """``camera``'s whole pinhole frame of ``renderer``'s scene without the arm, colour
    and depth, kept per scene state (see the module docstring)."""

    def __init__(self, renderer: Any, camera: str) -> None:
        self.renderer, self.camera = renderer, camera
        self.static = renderer.labels.kind != KINDS.index("arm")
        self._kept: OrderedDict[bytes, Layer] = OrderedDict()
        #: Whole frames drawn (for the tests and the benchmarks).
        self.drawn = 0

    def state(self) -> bytes:
        """What the kept frame depends on: the static geoms' places, sizes and groups, and
        the lights' strength (the window's dimming)."""
        m, s = self.renderer.model, self.static
        return b"".join(
            np.ascontiguousarray(a).tobytes()
            for a in (m.geom_pos[s], m.geom_size[s], self.renderer._groups[s],
                      m.light_diffuse, m.light_ambient, m.light_specular)
        )  # fmt: skip

    def layer(self) -> Layer:
        """The frame for the scene as it is now, drawn if no kept one matches."""
        key = self.state()
        if key in self._kept:
            self._kept.move_to_end(key)
            return self._kept[key]
        self._kept[key] = self._draw()
        self.drawn += 1
        while len(self._kept) > KEPT:
            self._kept.popitem(last=False)
        return self._kept[key]

    def _draw(self) -> Layer:
        rd, mj = self.renderer, self.renderer._mj
        mj.mj_kinematics(rd.model, rd.data)
        mj.mj_camlight(rd.model, rd.data)
        spec = rd.cameras[self.camera]
        with rd._culled(self.camera, spec.size, spec.principal, merged=True) as local:
            rd.model.geom_group[~self.static] = CULLED_GROUP
            r = rd._renderer(spec, local)
            r.update_scene(rd.data, camera=self.camera)
            return _read(rd, r)


class CompositedWindows:
    """C1's marker windows as the arm drawn over :class:`StaticScene` (module docstring)."""

    def __init__(self, renderer: Any, camera: str = "c1_left") -> None:
        self.renderer, self.camera = renderer, camera
        self.scene = StaticScene(renderer, camera)
        self._arm = np.flatnonzero(~self.scene.static)

    def render(self, origin: tuple[int, int], side: int) -> npt.NDArray[np.uint8] | None:
        """Colour (side, side, 3) BGR of the window as
        :meth:`~softarm.sim.render.renderer.BushRenderer.render_window` draws it, with
        the arm over the kept scene; None where the window reaches past the frame."""
        rd = self.renderer
        w, h = rd.cameras[self.camera].size
        x0, y0 = origin
        if x0 < 0 or y0 < 0 or x0 + side > w or y0 + side > h:
            return None
        state, slot = scene_state(rd.model, rd.data), ("composited", self.camera, origin, side)
        kept: npt.NDArray[np.uint8] | None = rd._last.get(slot, state)
        if kept is not None:  # nothing moved since this was drawn
            return kept
        colour, depth = self.scene.layer()
        below = (colour[y0 : y0 + side, x0 : x0 + side], depth[y0 : y0 + side, x0 : x0 + side])
        arm = self._arm_layer(origin, side)
        out: npt.NDArray[np.uint8] = np.ascontiguousarray(composite(below, arm)[..., ::-1])
        rd._last.put(slot, state, out)
        return out

    def _arm_layer(self, origin: tuple[int, int], side: int) -> Layer:
        """The window's render with the arm's geoms the culling keeps and the row's geoms
        that may shade them (:func:`arm_casters`), the rest left out."""
        rd = self.renderer
        m, d = rd.model, rd.data
        spec = rd.cameras[self.camera]
        with window_camera(rd._mj, m, d, spec, origin, side) as (window, principal):
            with rd._culled(self.camera, (side, side), principal, merged=True) as local:
                drawn = m.geom_group != CULLED_GROUP
                arm = self._arm[drawn[self._arm]]
                rest = np.flatnonzero(drawn & self.scene.static)
                keep = np.zeros(len(rest), bool)
                if rd._shadow_travel is not None and len(arm):
                    radii = geom_bounds(m, self._arm)
                    keep = arm_casters(d.geom_xpos[rest], radii[rest], d.geom_xpos[arm],
                                       radii[arm], rd._shadow_travel)  # fmt: skip
                m.geom_group[rest[~keep]] = CULLED_GROUP
                r = rd._renderer(window, local)
                r.update_scene(d, camera=self.camera)
                return _read(rd, r)
