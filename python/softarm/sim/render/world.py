"""The rendered bush world: a :class:`~softarm.sim.bush.Bush` drawn with leaves, clutter
and the arm, seen by C1 (the ZED2: a stereo pair with a 12 cm baseline, 1280 × 720 per
eye) and C2 (the eye-in-hand camera), with lens distortion, and the ground truth of every
frame (instance masks and depth).

C1's left eye is the eye-to-hand camera of the tag world (``SimCameras.T_base_c1``);
the right eye sits ``baseline`` along its +x, as the ZED2's do.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm._core import SoftArm
from softarm.checks import FloatArray
from softarm.sim.bush import PLUS_Y, Branch, Bush
from softarm.sim.render.distortion import Distorter
from softarm.sim.render.headroom import dimmed, window_share
from softarm.sim.render.labels import KINDS, GeomLabels
from softarm.sim.render.look import BushLook
from softarm.sim.render.mjcf import (
    ARM_SEGMENTS_PER_SECTION,
    ARM_TUBE_RADIUS,
    CameraSpec,
    SceneSpec,
)
from softarm.sim.render.renderer import BushRenderer, RenderedFrame
from softarm.sim.render.rig_motion import RigMotion
from softarm.sim.render.row import ROW_Y, Row
from softarm.sim.render.row_camera import RowCameras
from softarm.sim.render.row_look import RowLook
from softarm.sim.render.window_composite import CompositedWindows, quantised_share
from softarm.vision.camera_model import CameraModel
from softarm.vision.crop import ImageCrop
from softarm.vision.marker_body import SIMULATED_BODY, panel_corners
from softarm.vision.marker_body import marker_body as make_body
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["ZED2_BASELINE", "RenderedBush", "StereoCamera", "arm_sections"]

#: The ZED2's stereo baseline (m).
ZED2_BASELINE = 0.12
#: The cube's and the gripper's reach (m) from their centres, for the leaves they push.
CUBE_REACH = 0.07
GRIPPER_REACH = 0.04
#: The C1 window rendered around the marker cube while tracking it holds the cube's
#: panels' corners with WINDOW_PAD px to spare on each side (the tags' quiet zone and
#: the detector's adaptive threshold reach past the outline); its side is a multiple of
#: WINDOW_STEP px (one renderer, an OpenGL context, per side). The pinhole window
#: rendered for it is WINDOW_MARGIN px larger (the distortion's shift).
WINDOW_PAD = 16
WINDOW_STEP = 32
WINDOW_MARGIN = 24


def arm_sections(arm: SoftArm, q: FloatArray) -> list[FloatArray]:
    """(ARM_SEGMENTS_PER_SECTION + 1, 3) points along each section of the constant-
    curvature ``arm`` at elongations ``q``, for drawing."""
    s = np.linspace(0.0, 1.0, ARM_SEGMENTS_PER_SECTION + 1)
    return [np.array([arm.point(q, k, u)[0] for u in s]) for k in range(arm.n_sections)]


def polyline_sections(points: FloatArray, section_of: Sequence[int], n: int) -> list[FloatArray]:
    """A centre line (N, 3) whose nodes belong to sections ``section_of`` (the Cosserat
    rod's), resampled to ARM_SEGMENTS_PER_SECTION + 1 points per section by arc length."""
    out = []
    labels = np.asarray(section_of)
    for k in range(n):
        pts = points[labels == k]
        if len(pts) < 2:
            pts = np.vstack([pts, pts]) if len(pts) else np.zeros((2, 3))
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
        t = np.linspace(0.0, arc[-1], ARM_SEGMENTS_PER_SECTION + 1)
        out.append(np.column_stack([np.interp(t, arc, pts[:, i]) for i in range(3)]))
    return out


class RenderedBush:
    """The bush of ``bush`` as MuJoCo draws it (see the module docstring).

    Args:
        bush: berries (ripe and unripe) and canes.
        T_base_c1: the left eye of C1 in the base frame.
        c1: the intrinsics of each eye of C1 (with distortion and image size).
        c2: C2's intrinsics; ``T_ee_c2`` its pose on the end effector.
        T_ee_cube: the marker cube on the end effector; ``cube_marker`` its tags' side.
        T_base_tag, base_tag_id, base_tag: the base tag.
        look: the appearance; None draws one from the bush's seed. A
            :class:`~softarm.sim.render.row_look.RowLook` draws the bush inside a
            hedgerow in daylight (:mod:`softarm.sim.render.row`), every frame through
            the look's camera model (:mod:`softarm.sim.render.row_camera`).
        baseline: C1's stereo baseline (m).
        n_sections: sections of the arm drawn.
        shadows: in the row, the sun casts shadows (a shadow map; off: cheaper).
        marker_body: the body carrying the tags C1 tracks
            (:data:`~softarm.vision.marker_body.MARKER_BODIES`).
        composited_windows: in the row, C1's marker windows drawn as the arm over
            the row kept from an earlier render
            (:mod:`softarm.sim.render.window_composite`); off (the default): each
            drawn whole. Off because a harvest's CPU per simulated second is the same
            either way (BENCHMARKS.md, "The daylight row") while the pixels differ.
    """

    def __init__(
        self,
        bush: Bush,
        T_base_c1: FloatArray,
        c1: CameraModel,
        c2: CameraModel,
        T_ee_c2: FloatArray,
        T_ee_cube: FloatArray,
        T_base_tag: FloatArray,
        base_tag_id: int,
        base_tag: float,
        cube_marker: float = 0.08,
        look: BushLook | None = None,
        baseline: float = ZED2_BASELINE,
        n_sections: int = 3,
        shadows: bool = True,
        marker_body: str = SIMULATED_BODY,
        composited_windows: bool = False,
    ) -> None:
        self.bush = bush
        self.look = look or BushLook.random(bush.seed)
        self.row = Row.generate(bush, self.look) if isinstance(self.look, RowLook) else None
        T_left_right = np.eye(4)
        T_left_right[0, 3] = baseline
        self.stereo = StereoCamera(c1, c1, T_base_c1, T_left_right)
        self.motion = RigMotion(self.stereo, c2, T_ee_c2, _face(bush), rig_in_c2=self._rig_in_c2)
        self.effects = (
            RowCameras(self.look, self.motion) if isinstance(self.look, RowLook) else None
        )
        self.c2 = c2
        self.T_ee_cube = T_ee_cube
        body = make_body(marker_body, cube_marker)
        outline = panel_corners(body).reshape(-1, 3)
        self._cube_corners = outline
        self._tag_normals = np.stack([T[:3, 2] for T in body.markers.values()])  # body frame
        # The leaves the body pushes: as far as the cube's, plus what the body reaches past it.
        cube_outline = panel_corners(make_body("cube", cube_marker)).reshape(-1, 3)
        self._cube_reach = CUBE_REACH + float(
            np.linalg.norm(outline, axis=1).max() - np.linalg.norm(cube_outline, axis=1).max()
        )
        right = T_base_c1 @ T_left_right
        spec = SceneSpec(
            bush=bush,
            look=self.look,
            world_cameras=[_spec("c1_left", T_base_c1, c1), _spec("c1_right", right, c1)],
            hand_cameras=[_spec("c2", T_ee_c2, c2)],
            T_base_tag=T_base_tag,
            base_tag_id=base_tag_id,
            tag_length=base_tag,
            cube_marker=cube_marker,
            marker_body=marker_body,
            n_sections=n_sections,
            keep_clear=_approach_lines(bush),
            row=self.row,
            shadows=shadows,
        )
        self.renderer = BushRenderer(spec)
        self.windows = (
            CompositedWindows(self.renderer) if self.row is not None and composited_windows
            else None
        )  # fmt: skip
        self._distort = {"c1": Distorter(c1), "c2": Distorter(c2)}
        self.renderer.hide_arm()

    @property
    def labels(self) -> GeomLabels:
        """Which object each geom id of a frame's ``geoms`` belongs to."""
        return self.renderer.labels

    def set_arm(self, sections: Sequence[FloatArray], T_base_ee: FloatArray) -> None:
        """Draw the arm along ``sections`` (see :func:`arm_sections`) with its end
        effector, gripper, C2 and cube at ``T_base_ee``."""
        self.renderer.set_arm(sections, T_base_ee)
        cube = T_base_ee @ self.T_ee_cube
        self.renderer.set_cube(cube)
        body = [_densified(s) for s in sections] + [cube[None, :3, 3], T_base_ee[None, :3, 3]]
        radius = [np.full(len(b), ARM_TUBE_RADIUS) for b in body[:-2]] + [
            np.array([self._cube_reach]),
            np.array([GRIPPER_REACH]),
        ]
        self.renderer.push_leaves(np.vstack(body), np.concatenate(radius))
        self.motion.moved(T_base_ee, np.vstack(body), np.concatenate(radius))

    def set_clock(self, clock: Callable[[], float]) -> None:
        """Stamp each drawing of the arm with ``clock()`` (s): the row's frames then
        blur by the motion between drawings (:mod:`softarm.sim.render.rig_motion`)."""
        self.motion.clock = clock

    def hide_arm(self) -> None:
        """An empty view of the bush (no arm)."""
        self.renderer.hide_arm()

    def remove_berry(self, tag_id: int) -> None:
        """Take berry ``tag_id`` off the bush for good (picked): no frame draws it."""
        self.renderer.remove_berry(tag_id)

    def c1(self, truth: bool = False) -> tuple[RenderedFrame, RenderedFrame]:
        """C1's (left, right) images; with ``truth`` also depth and geom ids."""
        return self._frame("c1_left", "c1", truth), self._frame("c1_right", "c1", truth)

    def c1_left(self, truth: bool = False) -> RenderedFrame:
        """C1's left eye alone (the cube tracking needs one eye)."""
        return self._frame("c1_left", "c1", truth)

    def cube_window(self, T_base_cube: FloatArray) -> ImageCrop:
        """C1's left eye around the marker cube at ``T_base_cube`` (where it truly is,
        as the tag world's crop): the smallest square of WINDOW_STEP px steps, centred
        on the cube, that holds the corners of the body's panels with WINDOW_PAD px to spare.
        A software rasteriser's cost goes with the pixels."""
        T_c1_cube = invert(self.stereo.T_base_left) @ T_base_cube
        points = np.vstack([T_c1_cube[:3, 3], self._cube_corners @ T_c1_cube[:3, :3].T])
        points[1:] += T_c1_cube[:3, 3]
        if np.any(points[:, 2] <= 0.0):  # the cube at or behind C1: nothing to see
            return self.c1_left_window((0.0, 0.0), WINDOW_STEP)
        pixels = self.stereo.left.project(points)
        reach = float(np.abs(pixels[1:] - pixels[0]).max()) + WINDOW_PAD
        side = WINDOW_STEP * int(np.ceil(2.0 * reach / WINDOW_STEP))
        w, h = self.stereo.left.image_size or (side, side)
        centre = (float(pixels[0, 0]), float(pixels[0, 1]))
        share = 1.0  # the bush has no camera model: its render is delivered as drawn
        if self.effects is not None:
            normals = self._tag_normals @ T_base_cube[:3, :3].T
            share = window_share(self.renderer.model, normals)
            if self.windows is not None:  # the kept row serves nearby shares
                share = quantised_share(share)
        return self.c1_left_window(centre, min(side, w, h), share)

    def c1_left_window(
        self, centre: tuple[float, float], side: int, share: float = 1.0
    ) -> ImageCrop:
        """The ``side``-pixel square of C1's left eye around ``centre`` (px, clamped into
        the frame), with lens distortion, as an :class:`ImageCrop` that detectors read in
        full-frame coordinates. Only the pinhole pixels the window needs are rendered
        (:meth:`BushRenderer.render_window`; with ``composited_windows`` the arm over
        the row kept, :mod:`softarm.sim.render.window_composite`); they equal the full
        frame's. ``share``:
        the lights' strength it is drawn with, its camera's exposure scaled back
        (:mod:`softarm.sim.render.headroom`)."""
        w, h = self.stereo.left.image_size or (0, 0)
        x0 = int(np.clip(round(centre[0] - side / 2), 0, max(w - side, 0)))
        y0 = int(np.clip(round(centre[1] - side / 2), 0, max(h - side, 0)))
        d = self._distort["c1"]
        mx = d.map_x[y0 : y0 + side, x0 : x0 + side]
        my = d.map_y[y0 : y0 + side, x0 : x0 + side]
        px0, py0 = int(np.floor(mx.min())) - 2, int(np.floor(my.min())) - 2
        span = side + WINDOW_MARGIN
        if mx.max() - px0 >= span - 2 or my.max() - py0 >= span - 2:  # strong distortion
            return ImageCrop(
                self.c1_left().colour[y0 : y0 + side, x0 : x0 + side], (x0, y0), (w, h)
            )
        with dimmed(self.renderer.model, share):
            pin = None if self.windows is None else self.windows.render((px0, py0), span)
            if pin is None:  # no compositing, or the window reaches past the frame
                pin = self.renderer.render_window("c1_left", (px0, py0), span)
        colour = cv2.remap(
            pin, mx - px0, my - py0, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
        )
        if self.effects is not None:
            window = np.asarray(colour, np.uint8)
            colour = self.effects.apply("c1_window", window, (x0, y0), share)
        return ImageCrop(colour, (x0, y0), (w, h))

    def c2_frame(self, truth: bool = False) -> RenderedFrame:
        """C2's image from where the arm is drawn."""
        return self._frame("c2", "c2", truth)

    def _rig_in_c2(self) -> npt.NDArray[np.bool_]:
        """C2's pixels of the rig (fingers, marker body): the same in every C2 frame."""
        drawn = self.renderer.render("c2", geoms=True).geoms
        assert drawn is not None  # asked for
        geoms = self._distort["c2"].nearest(drawn)
        result: npt.NDArray[np.bool_] = self.labels.kinds(geoms) == KINDS.index("arm")
        return result

    def berry_outlines(self) -> RenderedFrame:
        """C1's left eye with only the berries drawn (geoms only): each berry's whole
        outline, against which its visible share is measured."""
        f = self.renderer.render("c1_left", geoms=True, occluders=False)
        d = self._distort["c1"]
        return RenderedFrame(f.colour, None, None if f.geoms is None else d.nearest(f.geoms))

    def berry_shares(self, seen: RenderedFrame | None = None) -> dict[int, float]:
        """Each berry's visible share in C1's left eye as the arm is drawn now (tag id
        -> its pixels in the whole scene over those of its outline alone, 0 when out of
        the picture); ``seen``: that eye's truth frame when already rendered."""
        if seen is None:
            seen = self.c1_left(truth=True)
        outline = self.berry_outlines()
        assert seen.geoms is not None and outline.geoms is not None  # asked for
        shares = {}
        for tag in self.fruit_ids():
            whole = self.labels.mask(outline.geoms, "berry", tag).sum()
            visible = self.labels.mask(seen.geoms, "berry", tag).sum()
            shares[tag] = float(visible / whole) if whole else 0.0
        return shares

    def fruit_ids(self) -> list[int]:
        """Every fruit drawn: the bush's berries (tag ids), then the row's."""
        if self.row is None:
            return [b.tag_id for b in self.bush.berries]
        return [f.fruit_id for f in self.row.fruit]

    def stage(self, fruit_id: int) -> str | None:
        """A fruit's stage (softarm.sim.render.row.STAGES): in the bush, ripe or
        unripe by its ripeness; None for no such fruit."""
        if self.row is not None:
            return self.row.stage(fruit_id)
        berry = next((b for b in self.bush.berries if b.tag_id == fruit_id), None)
        return None if berry is None else ("ripe" if berry.ripeness >= 0.5 else "unripe")

    def canes(self) -> list[Branch]:
        """Every cane drawn, by its id in the masks: the bush's, then the row's."""
        return [*self.bush.branches, *(self.row.canes if self.row is not None else [])]

    def close(self) -> None:
        """Free the renderer."""
        self.renderer.close()

    def _frame(self, camera: str, lens: str, truth: bool) -> RenderedFrame:
        f = self.renderer.render(camera, depth=truth, geoms=truth)
        d = self._distort[lens]
        colour = d.colour(f.colour)
        if self.effects is not None:
            colour = self.effects.apply(camera, colour)
        return RenderedFrame(
            colour,
            None if f.depth is None else d.nearest(f.depth),
            None if f.geoms is None else d.nearest(f.geoms),
        )


def _densified(points: FloatArray, per_segment: int = 3) -> FloatArray:
    """``points`` with ``per_segment`` - 1 more between each pair."""
    t = np.linspace(0.0, 1.0, per_segment, endpoint=False)
    dense = [a + np.outer(t, b - a) for a, b in itertools.pairwise(points)]
    return np.vstack([*dense, points[-1:]])


def _spec(name: str, pose: FloatArray, camera: CameraModel) -> CameraSpec:
    K = camera.matrix
    size = camera.image_size or (int(2 * K[0, 2] + 1), int(2 * K[1, 2] + 1))
    return CameraSpec(name, pose, size, float(K[0, 0]), (float(K[0, 2]), float(K[1, 2])))


def _face(bush: Bush) -> tuple[FloatArray, FloatArray]:
    """The bush's face: the plane through its berries' centre facing the arm (-Y), the
    scene C2 looks at (its motion blur's depth)."""
    if not bush.berries:
        return np.array([0.0, ROW_Y, 0.0]), PLUS_Y
    return np.mean([b.position for b in bush.berries], axis=0), PLUS_Y


def _approach_lines(bush: Bush) -> list[tuple[FloatArray, FloatArray]]:
    """The last 8 cm before each berry along +Y: leaves stay out of them, as a gripper
    on a real bush pushes a leaf in its way aside."""
    return [(b.position - 0.08 * PLUS_Y, b.position) for b in bush.berries]


def world_for(
    bush: Bush, cams: Any, base_tag_id: int, look: BushLook | None = None, c2_scale: float = 1.0
) -> RenderedBush:
    """The rendered world of ``bush`` seen by the simulated rig's cameras ``cams`` (a
    ``softarm.sim.rig_cameras.SimCameras``: C1's left eye where the tag world's
    eye-to-hand camera is); ``c2_scale`` shrinks C2's image and focal length."""
    return RenderedBush(
        bush, cams.T_base_c1, cams.model(1), scaled(cams.model(2), c2_scale), cams.T_ee_c2,
        cams.T_ee_cube,
        cams.T_base_tag, base_tag_id, cams.base_tag, cams.cube_marker, look,
        marker_body=getattr(cams, "marker_body", SIMULATED_BODY),
    )  # fmt: skip


def scaled(camera: CameraModel, scale: float) -> CameraModel:
    """``camera`` with its image and focal length scaled by ``scale`` (same field of
    view, same distortion)."""
    if scale == 1.0:
        return camera
    w, h = camera.image_size or (0, 0)
    size = (round(w * scale), round(h * scale))
    K = camera.matrix.copy()
    K[:2] *= scale
    K[0, 2], K[1, 2] = (size[0] - 1) / 2, (size[1] - 1) / 2
    return CameraModel(K, camera.distortion, size)
