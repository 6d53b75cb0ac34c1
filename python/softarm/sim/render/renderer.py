"""MuJoCo's offscreen renderer on a bush scene: colour, depth and per-geom segmentation
from any camera of the scene, with the arm moved each frame.

Rendering is MuJoCo's OpenGL rasteriser through EGL (``MUJOCO_GL=egl``; on machines
without a GPU, Mesa's software rasteriser). The bush: one directional light plus
ambient, no shadows; the row: a sun with a shadow map, which a small render (C2, a C1
window) draws small, at the full map's texel pitch, about what it sees
(:mod:`softarm.sim.render.shadow_map`). Geoms that cannot show in a render are left out
of it (:mod:`softarm.sim.render.culling`), and a small colour render draws the row's
bush canes as merged meshes of fewer triangles (:mod:`softarm.sim.render.cane_mesh`).
In the small renders the row's ground plane casts no shadow (:meth:`BushRenderer._draw`).
C1's marker windows can be drawn as the arm over the row kept from one whole render
(:mod:`softarm.sim.render.window_composite`; off by default).
Lens distortion is applied afterwards (:mod:`softarm.sim.render.distortion`).
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

from softarm.checks import FloatArray
from softarm.errors import MissingDependencyError
from softarm.sim.render.cane_mesh import merged_and_members
from softarm.sim.render.culling import in_frustum
from softarm.sim.render.ground_shadow import (
    ground_casters,
    ground_height,
    leave_out_of_depth_pass,
)
from softarm.sim.render.labels import KINDS, GeomLabels
from softarm.sim.render.last_render import LastRender, scene_state
from softarm.sim.render.mjcf import (
    ARM_SEGMENTS_PER_SECTION,
    CameraSpec,
    SceneSpec,
    scene_xml,
)
from softarm.sim.render.shadow_casters import shadow_casters
from softarm.sim.render.shadow_map import (
    BACKDROP_RADIUS,
    LOCAL_MAX_PIXELS,
    LOCAL_SIZE,
    SunShadows,
)
from softarm.sim.render.window_camera import geom_bounds as _bounds
from softarm.sim.render.window_camera import window_camera
from softarm.uninterrupted import uninterrupted

#: Where what is out of the picture is put.
FAR_AWAY = np.array([0.0, -50.0, 0.0])
#: The geom group of everything that can hide a berry (leaves, canes, clutter, the arm).
OCCLUDER_GROUP = 2
#: The geom group a geom outside a render's frustum is moved to for that render: MuJoCo's
#: default visualisation options, and those :meth:`BushRenderer.render` builds, hide it.
CULLED_GROUP = 5
#: The ground planes' grid pitch (m) in the small renders' context (C2, C1's windows,
#: with the small shadow map). MuJoCo draws a plane as a grid of quads, made when the
#: context is made, for the per-vertex light of spot and point lights; the row's lights
#: are directional, so the grid changes no lit colour, while its finest grid (200 x 200
#: quads, drawn in each of a shadowed render's three passes) was a fifth of a small
#: render's cost. At 4 m the row's 80 m ground is 12 x 12 quads. A whole C1 frame keeps
#: the fine grid: there the longer triangles' texture coordinates round a few hundred
#: pixels of open soil onto the next texel of its speckle (up to 4 levels), and the
#: cane fit read them (7 canes instead of 8 on row 90140).
SMALL_RENDER_GROUND_GRID = 4.0

__all__ = ["BushRenderer", "RenderUnavailableError", "RenderedFrame", "require_mujoco"]


class RenderUnavailableError(MissingDependencyError):
    """The rendered world cannot run here: MuJoCo (the ``render`` extra) or an offscreen
    OpenGL (a system library no extra installs: the message says which to set up) is
    missing. A :class:`~softarm.errors.MissingDependencyError` whose ``extra`` is
    ``"render"``, so that one ``except`` covers every optional part that is absent."""

    def __init__(self, message: str, extra: str = "render") -> None:
        super().__init__(message, extra)


HOW_TO_ENABLE = (
    "the rendered bush needs MuJoCo (pip install 'softarm[render]') and an offscreen OpenGL: set "
    "MUJOCO_GL=egl with an EGL driver (Mesa's libegl1 on a machine without a GPU, the "
    "NVIDIA driver on one with it) or MUJOCO_GL=osmesa; or use --world tags"
)


def require_mujoco() -> Any:
    """The ``mujoco`` module with an offscreen backend selected (EGL unless the caller
    chose one), or :class:`RenderUnavailableError` saying how to enable it."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        import mujoco
    except (ImportError, OSError, AttributeError, RuntimeError) as exc:  # no GL library
        raise RenderUnavailableError(f"{HOW_TO_ENABLE} ({exc})") from exc
    return mujoco


@dataclass(frozen=True)
class RenderedFrame:
    """One camera's image: ``colour`` (H, W, 3) BGR uint8 as OpenCV reads it, ``depth``
    (H, W) float32 metres along the optical axis (NaN: nothing drawn), ``geoms`` (H, W)
    int32 geom ids (-1: nothing); depth and geoms only when asked for."""

    colour: npt.NDArray[np.uint8]
    depth: npt.NDArray[np.float32] | None = None
    geoms: npt.NDArray[np.int32] | None = None


class BushRenderer:
    """Renders the scene of ``spec``; :meth:`set_arm` moves the arm, :meth:`render`
    draws one camera.

    Raises:
        RenderUnavailableError: no MuJoCo or no offscreen OpenGL (the message says how
            to enable it).
    """

    def __init__(self, spec: SceneSpec) -> None:
        mujoco = require_mujoco()
        self._mj = mujoco
        xml, assets = scene_xml(spec)
        self.model = mujoco.MjModel.from_xml_string(xml, assets)
        self.data = mujoco.MjData(self.model)
        self.cameras = {c.name: c for c in [*spec.world_cameras, *spec.hand_cameras]}
        self.labels = GeomLabels.from_model(self.model, mujoco)
        #: One context per offscreen buffer size and shadow map (:meth:`_renderer`).
        self._renderers: dict[tuple[int, int, bool], Any] = {}
        self._last = LastRender()
        self._mocap = {
            self.model.body(i).name: self.model.body_mocapid[i]
            for i in range(self.model.nbody)
            if self.model.body_mocapid[i] >= 0
        }
        self._seg_geoms = [
            mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, f"arm_seg{k}")
            for k in range(spec.n_sections * ARM_SEGMENTS_PER_SECTION)
        ]
        self.n_sections = spec.n_sections
        self._arm_set = False
        self._leaves = np.flatnonzero(self.labels.kind == KINDS.index("leaf"))
        self._leaf_home = self.model.geom_pos[self._leaves].copy()
        self._leaf_half = self.model.geom_size[self._leaves, 0].copy()
        # Every geom may be culled, the arm's by a sphere their sizes bound (_bounds).
        self._groups = self.model.geom_group.copy()
        self._cullable = np.arange(self.model.ngeom)
        self._arm = np.flatnonzero(self.labels.kind == KINDS.index("arm"))
        self._backdrop = self.model.geom_rbound > BACKDROP_RADIUS
        self._planes = np.flatnonzero(self.model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
        self._ground = ground_height(self.model, self._planes)
        self._backdrop[self._arm] = False
        self._merged, self._members = merged_and_members(self.model, self.labels)
        self._shadow_travel: FloatArray | None = None
        self._sun: SunShadows | None = None
        if spec.row is not None and spec.shadows:
            sun = np.asarray(spec.look.light_direction, float)
            self._shadow_travel = sun / np.linalg.norm(sun)
            self._sun = SunShadows(self.model, mujoco)
        #: Geoms left out of the sun's depth pass in the small renders (:meth:`_draw`).
        self._no_shadow = ground_casters(self._planes, self._shadow_travel)

    def push_leaves(self, body: FloatArray, radius: FloatArray) -> None:
        """Move aside every leaf that the arm's body (spheres at ``body`` (N, 3) with
        ``radius`` (N,)) would pass through: a real leaf is pushed by the arm, a
        rendered one would otherwise stay inside it and hide the cube from C1 and the
        fruit from C2 as no leaf on a bush can. A leaf is in the way when its centre lies
        within the body's radius plus half the leaf's half-length."""
        gaps = np.linalg.norm(self._leaf_home[:, None, :] - body[None, :, :], axis=2)
        inside = (gaps - radius[None, :] < 0.5 * self._leaf_half[:, None]).any(axis=1)
        self.model.geom_pos[self._leaves] = self._leaf_home
        self.model.geom_pos[self._leaves[inside]] = FAR_AWAY

    def remove_berry(self, tag_id: int) -> None:
        """Take berry ``tag_id`` off the bush for good (picked): its geoms join the
        group no render draws."""
        berry = (self.labels.kind == KINDS.index("berry")) & (self.labels.instance == tag_id)
        self._groups[berry] = CULLED_GROUP
        self.model.geom_group[berry] = CULLED_GROUP

    def set_arm(self, sections: Sequence[FloatArray], T_base_ee: FloatArray) -> None:
        """Draw the arm: ``sections`` are (ARM_SEGMENTS_PER_SECTION + 1, 3) points along
        each section's centre line (base frame), ``T_base_ee`` the end effector; the
        gripper, hand cameras and cube ride on the end effector."""
        k = 0
        for points in sections:
            for a, b in itertools.pairwise(points):
                self._place_quat(f"arm_seg{k}", 0.5 * (a + b), _quat_z_to(b - a))
                self.model.geom_size[self._seg_geoms[k], 1] = max(
                    0.5 * float(np.linalg.norm(b - a)), 1e-4
                )
                k += 1
        ends = [s[0] for s in sections] + [sections[-1][-1]]
        tangents = [s[1] - s[0] for s in sections] + [sections[-1][-1] - sections[-1][-2]]
        for i, (p, t) in enumerate(zip(ends, tangents, strict=True)):
            self._place_quat(f"arm_plate{i}", p, _quat_z_to(t))
        self._place("arm_ee", T_base_ee[:3, 3], T_base_ee[:3, :3])
        self._arm_set = True

    def set_cube(self, T_base_cube: FloatArray) -> None:
        """Place the marker cube (it rides on the end effector: call after set_arm)."""
        self._place("arm_cube", T_base_cube[:3, 3], T_base_cube[:3, :3])

    def hide_arm(self) -> None:
        """Move the arm out of sight (an empty bush, as at registration or a dataset),
        the leaves back where they grow."""
        for name in self._mocap:
            self._place(name, FAR_AWAY, np.eye(3))
        self.model.geom_pos[self._leaves] = self._leaf_home
        self._arm_set = False

    def render(
        self, camera: str, depth: bool = False, geoms: bool = False, occluders: bool = True
    ) -> RenderedFrame:
        """One image of ``camera`` (a name of the scene) as it is now; without
        ``occluders`` only the background and the berries are drawn (the berries' whole
        outlines, for their visible fraction)."""
        state, slot = scene_state(self.model, self.data), (camera, depth, geoms, occluders)
        kept: RenderedFrame | None = self._last.get(slot, state)
        if kept is not None:  # nothing moved since this was drawn
            return kept
        mj = self._mj
        mj.mj_kinematics(self.model, self.data)
        mj.mj_camlight(self.model, self.data)  # camera and light poses from the bodies
        spec = self.cameras[camera]
        option = mj.MjvOption()
        option.geomgroup[OCCLUDER_GROUP] = int(occluders)
        merged = not (depth or geoms) and spec.size[0] * spec.size[1] <= LOCAL_MAX_PIXELS
        with self._culled(camera, spec.size, spec.principal, merged) as local:
            r = self._renderer(spec, local)
            drawn = self._render_passes(r, camera, option, depth, geoms, local)
            return self._last.put(slot, state, drawn)

    def _render_passes(
        self, r: Any, camera: str, option: Any, depth: bool, geoms: bool, local: bool = False
    ) -> RenderedFrame:
        """Colour, and depth and geom ids if asked, of ``camera`` with renderer ``r``
        (``local``: with the small shadow map, :meth:`_draw`)."""
        r.update_scene(self.data, camera=camera, scene_option=option)
        colour = np.ascontiguousarray(self._draw(r, local)[..., ::-1])
        d = _depth_pass(r, self.data, camera, option) if depth else None
        s = _geom_pass(r, self.data, camera, option, self._mj) if geoms else None
        if d is not None and s is not None:
            d[s < 0] = np.nan
        return RenderedFrame(colour, d, s)

    def visible_share(self, camera: str, geoms: Sequence[int]) -> float:
        """The share of the pixels ``geoms`` cover in ``camera``'s image drawn alone
        that they still cover with the whole scene drawn (0 when they are out of the
        picture): how much of an object the rest of the scene hides."""
        ids = np.asarray(geoms)
        seen = self.render(camera, geoms=True).geoms
        others = np.setdiff1d(np.arange(self.model.ngeom), ids)
        self.model.geom_group[others] = CULLED_GROUP
        try:
            alone = self.render(camera, geoms=True).geoms
        finally:
            self.model.geom_group[:] = self._groups
        assert seen is not None and alone is not None  # asked for
        whole = int(np.isin(alone, ids).sum())
        return 0.0 if whole == 0 else int(np.isin(seen, ids).sum()) / whole

    def render_window(self, camera: str, origin: tuple[int, int], side: int) -> np.ndarray:
        """Colour (side, side, 3) BGR of the ``side``-pixel square of ``camera``'s pinhole
        image whose top-left pixel is ``origin`` (x0, y0), which may reach past the frame:
        the camera's principal point is moved for one render, so only the window's
        pixels are drawn (a software rasteriser's cost goes with them)."""
        state, slot = scene_state(self.model, self.data), (camera, origin, side)
        kept: np.ndarray | None = self._last.get(slot, state)
        if kept is not None:  # nothing moved since this was drawn
            return kept
        spec = self.cameras[camera]
        with window_camera(self._mj, self.model, self.data, spec, origin, side) as (window, pp):
            with self._culled(camera, (side, side), pp, merged=True) as local:
                r = self._renderer(window, local)
                r.update_scene(self.data, camera=camera)
                return self._last.put(
                    slot, state, np.ascontiguousarray(self._draw(r, local)[..., ::-1])
                )

    def _draw(self, r: Any, local: bool) -> npt.NDArray[np.uint8]:
        """The colour image of the scene renderer ``r`` was last given (``update_scene``);
        with the small shadow map (``local``) the ground plane left out of the sun's
        depth pass (:mod:`softarm.sim.render.ground_shadow`)."""
        if self._no_shadow and local:
            leave_out_of_depth_pass(r._scene, self._no_shadow, self._mj)
        image: npt.NDArray[np.uint8] = r.render()
        return image

    @contextmanager
    def _culled(
        self,
        camera: str,
        size: tuple[int, int],
        principal: tuple[float, float],
        merged: bool = False,
    ) -> Iterator[bool]:
        """Within the block, every geom that cannot show in ``camera``'s ``size``
        picture with ``principal`` point (px) is in :data:`CULLED_GROUP`
        (:mod:`softarm.sim.render.culling`; the camera's pose is the data's, after
        ``mj_camlight``), and with ``merged`` the canes are their merged meshes
        (:mod:`softarm.sim.render.cane_mesh`). Yields whether the render takes a small
        shadow map (:mod:`softarm.sim.render.shadow_map`)."""
        mj, m, d = self._mj, self.model, self.data
        if merged:  # the capsules out, their meshes in
            m.geom_group[self._members], m.geom_group[self._merged] = CULLED_GROUP, OCCLUDER_GROUP
        cam = mj.mj_name2id(m, mj.mjtObj.mjOBJ_CAMERA, camera)
        centres = (d.geom_xpos[self._cullable] - d.cam_xpos[cam]) @ d.cam_xmat[cam].reshape(3, 3)
        radii = _bounds(m, self._arm)[self._cullable]
        focal = self.cameras[camera].focal
        shown = in_frustum(centres, radii, size, focal, principal)
        local = False
        light = None if self._sun is None else d.light_xpos[self._sun.light].copy()
        if self._sun is not None and size[0] * size[1] <= LOCAL_MAX_PIXELS:
            local = self._sun.place(d, *self._seen(cam, size, focal, principal))
        if self._shadow_travel is not None:  # a caster out of the picture may shade it
            travel = self._shadow_travel @ d.cam_xmat[cam].reshape(3, 3)
            seen = shown.copy()
            heights = d.geom_xpos[self._cullable, 2]
            shown |= shadow_casters(centres, heights, radii, travel, self._shadow_travel[2],
                                    self._ground, (size, focal, principal))  # fmt: skip
            if local and self._sun is not None:  # a caster kept for its shadow alone
                # must reach into the small map
                shown &= seen | self._sun.in_map(d, d.geom_xpos[self._cullable], radii)
        m.geom_group[self._cullable[~shown]] = CULLED_GROUP
        try:
            yield local
        finally:
            m.geom_group[:] = self._groups
            if self._sun is not None:
                d.light_xpos[self._sun.light] = light

    def _seen(
        self, cam: int, size: tuple[int, int], focal: float, principal: tuple[float, float]
    ) -> tuple[FloatArray, FloatArray]:
        """The bounding spheres (world centres, radii) of what camera ``cam`` can see,
        whatever the culling: every geom in its frustum but planes (unbounded) and the
        backdrop (larger than BACKDROP_RADIUS); the arm's geoms change size as it bends,
        so their size bounds their reach."""
        m, d = self.model, self.data
        radii = _bounds(m, self._arm)
        centres = (d.geom_xpos - d.cam_xpos[cam]) @ d.cam_xmat[cam].reshape(3, 3)
        seen = in_frustum(centres, radii, size, focal, principal) & (radii > 0)
        seen &= ~self._backdrop
        seen[self._merged] = False  # their capsules stand for them
        return d.geom_xpos[seen], radii[seen]

    def close(self) -> None:
        """Free the OpenGL contexts; a stop waits until they are freed (a context left
        half-destroyed fails its next free). Harmless twice."""
        with uninterrupted():
            while self._renderers:
                self._renderers.popitem()[1].close()

    def _renderer(self, spec: CameraSpec, local: bool = False) -> Any:
        """The renderer (an OpenGL context) set to ``spec``'s size; ``local``: with the
        small shadow map and the coarse ground (MuJoCo reads the map's settings and
        makes a plane's quads when it makes the context).

        One context serves every size its offscreen buffer holds: MuJoCo draws into
        that buffer's lower-left ``size`` pixels whatever size the context was made
        for, so only the viewport differs. Making a context costs half a second of
        CPU (every mesh and texture uploaded again), and the C1 windows come in many
        sizes."""
        w, h = spec.size
        m = self.model
        m.vis.global_.offwidth = max(m.vis.global_.offwidth, w)
        m.vis.global_.offheight = max(m.vis.global_.offheight, h)
        key = (int(m.vis.global_.offwidth), int(m.vis.global_.offheight), local)
        if key not in self._renderers:
            full = (int(m.vis.quality.shadowsize), float(m.vis.map.shadowclip))
            grids = m.geom_size[self._planes, 2].copy()
            if local and self._sun is not None:
                m.vis.quality.shadowsize = LOCAL_SIZE
                m.vis.map.shadowclip = self._sun.local_shadowclip
                m.geom_size[self._planes, 2] = SMALL_RENDER_GROUND_GRID
            try:
                self._renderers[key] = self._mj.Renderer(m, h, w)
            except (OSError, AttributeError, RuntimeError, self._mj.FatalError) as exc:  # no GL
                raise RenderUnavailableError(f"{HOW_TO_ENABLE} ({exc})") from exc
            finally:
                m.vis.quality.shadowsize, m.vis.map.shadowclip = full
                m.geom_size[self._planes, 2] = grids
        return _sized(self._renderers[key], self._mj, w, h)

    def _place(self, body: str, pos: FloatArray, R: FloatArray) -> None:
        x, y, z, w = Rotation.from_matrix(R).as_quat()
        self._place_quat(body, pos, np.array([w, x, y, z]))

    def _place_quat(self, body: str, pos: FloatArray, quat: FloatArray) -> None:
        i = self._mocap[body]
        self.data.mocap_pos[i] = pos
        self.data.mocap_quat[i] = quat


def _depth_pass(r: Any, data: Any, camera: str, option: Any) -> npt.NDArray[np.float32]:
    """Depth (m) of ``camera`` drawn by MuJoCo renderer ``r``."""
    r.enable_depth_rendering()
    r.update_scene(data, camera=camera, scene_option=option)
    depth: npt.NDArray[np.float32] = r.render().astype(np.float32)
    r.disable_depth_rendering()
    return depth


def _geom_pass(r: Any, data: Any, camera: str, option: Any, mj: Any) -> npt.NDArray[np.int32]:
    """The geom id of each pixel of ``camera`` drawn by ``r`` (-1: no geom)."""
    r.enable_segmentation_rendering()
    r.update_scene(data, camera=camera, scene_option=option)
    seg = r.render()
    r.disable_segmentation_rendering()
    ids = np.where(seg[..., 1] == int(mj.mjtObj.mjOBJ_GEOM), seg[..., 0], -1)
    return ids.astype(np.int32)


def _sized(r: Any, mj: Any, w: int, h: int) -> Any:
    """``mujoco.Renderer`` ``r`` set to draw and read ``w`` x ``h`` pixels: its image
    size is its viewport (``_rect``) and its read-back's shape, which the class fixes
    when it is made; the offscreen buffer must hold the size (:meth:`_renderer`)."""
    if (r._width, r._height) != (w, h):
        r._width, r._height = w, h
        r._rect = mj.MjrRect(0, 0, w, h)
    return r


def _quat_z_to(direction: FloatArray) -> FloatArray:
    """The quaternion (w, x, y, z) turning +z onto ``direction`` the shortest way: half
    way between them, [1 + z·d, z × d] normalised (a closed form: the arm is placed
    every frame, and a general rotation fit cost a third of the frame)."""
    n = float(np.linalg.norm(direction))
    if n < 1e-12:
        return np.array([1.0, 0.0, 0.0, 0.0])
    d = direction / n
    if d[2] < -1.0 + 1e-9:  # straight down: any half-turn about a horizontal axis
        return np.array([0.0, 1.0, 0.0, 0.0])
    q = np.array([1.0 + d[2], -d[1], d[0], 0.0])
    return q / np.linalg.norm(q)
