"""A synthetic pinhole camera with lens distortion that renders ArUco scenes.

Rendering is by inverse mapping, only inside each plane's projected bounding box: every
pixel is split into ``supersample``² sub-samples; each sub-sample's pixel position is
undistorted to a ray (from a per-camera table of normalised coordinates at pixel corners,
bilinearly interpolated), the ray is intersected with the plane (a homography, since the
plane is flat), and the texture is sampled there with ``cv2.remap``. Averaging the
sub-samples (box filter) gives anti-aliased edges; the texture resolution is chosen so that
one texel is about one sub-sample. Planes are drawn far to near (painter's algorithm);
back-facing planes are culled. Then optional Gaussian blur, then Gaussian noise.

Speed (the simulated harvest renders two images per control period):

- the sub-sample rays of the whole frame are interpolated once per camera (when the table
  fits in :data:`MAX_RAY_TABLE_BYTES`), so a plane's rays are a slice of it;
- a marker's coverage and colour are kept for the next frame, so a marker that does not
  move (the base tag) is drawn once;
- :meth:`SyntheticCamera.render_crop` renders only the window that holds the planes, plus
  a margin, and returns it as an :class:`~softarm.vision.crop.ImageCrop` that the detector
  reads in full-frame coordinates. Before noise its pixels equal those of
  :meth:`SyntheticCamera.render` in that window bit for bit; the noise has the same
  distribution, drawn for the window only (drawing it costs in proportion to the pixels).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, cast, overload

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import ParameterError
from softarm.sim.markers import SceneMarker, TexturedPlane
from softarm.vision.camera_model import CameraModel
from softarm.vision.crop import ImageCrop

SceneItem = SceneMarker | TexturedPlane
Box = tuple[int, int, int, int]  # pixel bounding box [x0, x1) x [y0, y1) as (x0, y0, x1, y1)

#: The largest whole-frame sub-sample ray table kept per camera (two float32 planes); a
#: larger one (a big frame at a high ``supersample``) is interpolated per plane instead.
MAX_RAY_TABLE_BYTES = 64 * 2**20
#: Drawn markers kept for reuse per camera (a static marker hits, a moving one misses).
_PATCH_CACHE_SIZE = 32


@dataclass(frozen=True)
class Scene:
    """What the camera sees: ``items`` (markers or textured planes) over a uniform
    ``background`` gray level (0–255)."""

    items: Sequence[SceneItem] = field(default_factory=list)
    background: float = 128.0


@dataclass(frozen=True)
class Lighting:
    """Print levels and shading: ``black``/``white`` are the gray levels of ink and paper
    facing the light; ``ambient`` ∈ [0, 1] is the unshaded fraction (1 = no shading);
    ``light_direction`` points from the scene towards the light, in the camera frame;
    ``vignetting`` darkens the corners by that fraction."""

    black: float = 25.0
    white: float = 225.0
    ambient: float = 1.0
    light_direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    vignetting: float = 0.0


@dataclass(frozen=True)
class _Layer:
    """One plane to draw: the scene item, its textured plane, pixel box and normal."""

    item: SceneItem
    plane: TexturedPlane
    box: Box
    normal: FloatArray


class SyntheticCamera:
    """Renders :class:`Scene` images through ``model`` at ``width`` x ``height`` pixels.

    ``noise_std`` is the Gaussian pixel noise (gray levels), ``blur`` the Gaussian blur
    sigma (pixels, 0 = none), ``supersample`` the sub-samples per pixel side, ``seed``
    the noise generator's seed.
    """

    def __init__(
        self,
        model: CameraModel,
        width: int,
        height: int,
        *,
        noise_std: float = 0.0,
        blur: float = 0.0,
        supersample: int = 4,
        lighting: Lighting | None = None,
        seed: int | None = None,
    ) -> None:
        if int(width) <= 0 or int(height) <= 0:
            raise ParameterError(f"width and height must be > 0, got {width}x{height}")
        if not noise_std >= 0 or not blur >= 0:
            raise ParameterError(f"noise_std and blur must be >= 0, got {noise_std}, {blur}")
        if not 1 <= int(supersample) <= 16:
            raise ParameterError(f"supersample must be in [1, 16], got {supersample}")
        self.model = model
        self.width, self.height = int(width), int(height)
        self.noise_std, self.blur = float(noise_std), float(blur)
        self.supersample = int(supersample)
        self.lighting = lighting or Lighting()
        self._noise = NoiseBank(self.width, self.height, seed)
        self._pixel_rays = PixelRays(model, self.width, self.height, self.supersample)
        self._patches: OrderedDict[tuple[object, ...], Any] = OrderedDict()
        self._planes: dict[tuple[object, ...], tuple[TexturedPlane, Box | None]] = {}
        self._vignette_cache: tuple[float, npt.NDArray[np.float32]] | None = None

    def render(
        self, scene: Scene | Sequence[SceneItem], background: float | None = None
    ) -> npt.NDArray[np.uint8]:
        """Render ``scene`` to a (height, width) uint8 gray image."""
        scene = _as_scene(scene, background)
        return self._image(scene.background, self._layers(scene), (0, 0, self.width, self.height))

    def render_crop(
        self,
        scene: Scene | Sequence[SceneItem],
        background: float | None = None,
        margin: int = 16,
        around: Callable[[SceneItem], bool] | None = None,
    ) -> ImageCrop:
        """Render only the window of the frame that holds ``scene``'s visible planes, grown
        by ``margin`` pixels (and by the blur's reach) on each side and clipped to the frame.

        Before noise the pixels equal those of :meth:`render` in that window (exactly with
        ``blur`` = 0; with blur, up to the frame's own border handling, which the margin
        keeps away from the planes); the noise has the same distribution, drawn for the
        window only. With nothing visible the window is the frame's top-left 16 x 16 pixels.

        ``around`` picks the planes the window is made to hold (a region of interest: the
        markers a tracker looks for); every plane that reaches into the window is drawn
        in it all the same, so the window shows the scene as the whole frame would.
        """
        if int(margin) < 0:
            raise ParameterError(f"margin must be >= 0, got {margin!r}")
        scene = _as_scene(scene, background)
        layers = self._layers(scene)
        held = layers if around is None else [la for la in layers if around(la.item)]
        if held:
            boxes = np.array([layer.box for layer in held])
            grow = int(margin) + int(np.ceil(4.0 * self.blur))
            box = (
                max(int(boxes[:, 0].min()) - grow, 0),
                max(int(boxes[:, 1].min()) - grow, 0),
                min(int(boxes[:, 2].max()) + grow, self.width),
                min(int(boxes[:, 3].max()) + grow, self.height),
            )
        else:
            box = (0, 0, min(16, self.width), min(16, self.height))
        img = self._image(scene.background, layers, box)
        return ImageCrop(img, box[:2], (self.width, self.height))

    def _layers(self, scene: Scene) -> list[_Layer]:
        """The visible planes of ``scene``, far to near, with their pixel boxes."""
        items = sorted(scene.items, key=lambda it: -float(np.linalg.norm(_pose_of(it)[:3, 3])))
        out = []
        for item in items:
            pose = _pose_of(item)
            rot, t = pose[:3, :3], pose[:3, 3]
            normal = rot[:, 2]
            if float(normal @ t) >= 0.0:  # back face: the camera is behind the plane
                continue
            if isinstance(item, SceneMarker):
                plane, box = self._marker_plane(item)
            else:
                plane, box = item, self._bbox(item)
            if box is not None:
                out.append(_Layer(item, plane, box, normal))
        return out

    def _marker_plane(self, item: SceneMarker) -> tuple[TexturedPlane, Box | None]:
        """The marker's textured plane (one texel per sub-sample where it is nearest) and
        pixel box; kept for the next frame, where a marker that does not move reuses it."""
        key: tuple[object, ...] = (item.marker_id, item.dictionary, item.marker_length, item.border)
        key += (item.T_camera_marker.tobytes(),)
        hit = self._planes.get(key)
        if hit is not None:
            return hit
        cells = item.marker_length / (_marker_cells(item) or 1)
        z_near = max(float(item.T_camera_marker[2, 3]) - item.marker_length, 1e-3)
        px_per_cell = self.model.focal * cells / z_near
        plane = item.to_plane(int(np.ceil(self.supersample * px_per_cell)))
        out = (plane, self._bbox(plane))
        self._planes[key] = out
        if len(self._planes) > _PATCH_CACHE_SIZE:
            self._planes.pop(next(iter(self._planes)))
        return out

    def _image(self, background: float, layers: list[_Layer], box: Box) -> npt.NDArray[np.uint8]:
        """The uint8 pixels of window ``box``: planes, vignetting, blur, noise."""
        x0, y0, x1, y1 = box
        img = np.full((y1 - y0, x1 - x0), background, np.float32)
        drawn: list[Box] = []
        for layer in layers:
            bx0, by0, bx1, by1 = layer.box
            if bx0 >= x1 or by0 >= y1 or bx1 <= x0 or by1 <= y0:
                continue
            # Clip to the window (render_crop's window holds every box whole).
            cx0, cy0, cx1, cy1 = max(bx0, x0), max(by0, y0), min(bx1, x1), min(by1, y1)
            sub = (slice(cy0 - by0, cy1 - by0), slice(cx0 - bx0, cx1 - bx0))
            region = img[cy0 - y0 : cy1 - y0, cx0 - x0 : cx1 - x0]
            if not any(_overlap(layer.box, b) for b in drawn):
                # Over the plain background the blend is linear in the texture: one channel.
                region += self._coverage(layer, background)[sub]
            else:
                alpha, color = self._coverage(layer)
                region *= 1.0 - alpha[sub]
                region += color[sub]
            drawn.append(layer.box)
        light = self.lighting
        if light.vignetting > 0:
            img *= self._vignette(light.vignetting)[y0:y1, x0:x1]
        if self.blur > 0:
            img = np.asarray(cv2.GaussianBlur(img, (0, 0), self.blur), dtype=np.float32)
        if self.noise_std > 0:
            frame, flip = self._noise.draw(y1 - y0, x1 - x0)
            noise = np.float32(self.noise_std) * frame
            img += -noise if flip else noise
        np.maximum(img, 0.0, out=img)
        # Rounds to nearest and saturates at 255 (values are >= 0 here, so abs is a no-op).
        return np.asarray(cv2.convertScaleAbs(img), dtype=np.uint8)

    @overload
    def _coverage(
        self, layer: _Layer
    ) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...

    @overload
    def _coverage(self, layer: _Layer, background: float) -> npt.NDArray[np.float32]: ...

    def _coverage(self, layer: _Layer, background: float | None = None) -> Any:
        """How one plane changes the pixels of its box. Without ``background``: (alpha,
        premultiplied colour), composited as ``pixel = pixel * (1 - alpha) + colour``. With
        it, over that plain gray: the change ``pixel - background``, which is linear in the
        texture (one channel to sample instead of two). Markers are looked up first: the
        same marker at the same pose and lighting draws the same pixels."""
        item = layer.item
        key = None
        if isinstance(item, SceneMarker):
            key = (
                item.marker_id, item.dictionary, item.marker_length, item.border,
                item.T_camera_marker.tobytes(), self.lighting, background,
            )  # fmt: skip
            hit = self._patches.get(key)
            if hit is not None:
                self._patches.move_to_end(key)
                return hit
        out = self._draw(layer, background)
        if key is not None:
            self._patches[key] = out
            if len(self._patches) > _PATCH_CACHE_SIZE:
                self._patches.popitem(last=False)
        return out

    def _draw(self, layer: _Layer, background: float | None) -> Any:
        """:meth:`_coverage` without the cache."""
        item = layer.plane
        pose = item.T_camera_plane
        rot, t = pose[:3, :3], pose[:3, 3]
        x0, y0, x1, y1 = layer.box
        rays = self._pixel_rays.of(layer.box)
        # Ray-plane intersection as a homography: (u, v, 1) ∝ [r1 r2 t]⁻¹ (x, y, 1).
        hinv = np.linalg.inv(np.column_stack([rot[:, 0], rot[:, 1], t]))
        tex = item.texture
        th, tw = tex.shape
        # Fold the metric-to-texel map into the homography: one projective map. Texel
        # centres are at integer map coordinates (the cv2.remap convention), shifted by the
        # one transparent texel padded around each texture (see _premultiplied).
        to_tex = np.array(
            [
                [tw / item.width, 0.0, 0.5 * tw + 0.5],
                [0.0, -th / item.height, 0.5 * th + 0.5],
                [0, 0, 1],
            ]
        )
        # One pass in C++ (double precision inside). A ray that misses the plane (w <= 0)
        # maps outside the texture, since the whole plane lies in front of the camera
        # (_bbox); perspectiveTransform sends w ≈ 0 to (0, 0), the transparent pad texel.
        maps = cv2.perspectiveTransform(rays, to_tex @ hinv)
        # Fixed-point maps: the same 1/32-texel rounding that remap applies to float maps
        # block by block, done in one pass.
        fixed, frac = cv2.convertMaps(maps, None, cv2.CV_16SC2)  # type: ignore[call-overload]  # map2 None is valid
        shade = self._shade(layer.normal)
        light = self.lighting
        ink = shade * light.black
        paper = shade * (light.white - light.black)
        if background is not None:
            # Outside the texture remap gives 0, i.e. no change: sample ink - background +
            # paper * reflectance, box-filter it, and it is exactly the blend below less
            # the background, alpha (background - ink) + paper * premultiplied reflectance.
            change = _affine(tex, ink - background, paper)
            sampled = cv2.remap(
                change, fixed, frac, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT
            )
            return cv2.resize(sampled, (x1 - x0, y1 - y0), interpolation=cv2.INTER_AREA)
        rgba = _premultiplied(tex)
        sampled = cv2.remap(rgba, fixed, frac, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
        small = cv2.resize(sampled, (x1 - x0, y1 - y0), interpolation=cv2.INTER_AREA)
        refl, alpha = small[..., 0], small[..., 1]
        color = ink * alpha + paper * refl
        return alpha, color

    def _bbox(self, plane: TexturedPlane) -> Box | None:
        """Pixel bounding box [x0, x1) x [y0, y1) of the plane's projection, or None."""
        outline = _UNIT_OUTLINE * [plane.width, plane.height]
        pose = plane.T_camera_plane
        pts = outline @ pose[:3, :2].T + pose[:3, 3]
        if np.any(pts[:, 2] <= 1e-3):
            return None  # straddles the camera plane: not drawn (documented limitation)
        # CameraModel.project without its argument checks (the points are ours).
        pix, _ = cv2.projectPoints(
            pts, np.zeros(3), np.zeros(3), self.model.matrix, self.model.distortion
        )
        pix = pix.reshape(-1, 2)
        x0 = max(int(np.floor(pix[:, 0].min())) - 2, 0)
        y0 = max(int(np.floor(pix[:, 1].min())) - 2, 0)
        x1 = min(int(np.ceil(pix[:, 0].max())) + 3, self.width)
        y1 = min(int(np.ceil(pix[:, 1].max())) + 3, self.height)
        return None if x0 >= x1 or y0 >= y1 else (x0, y0, x1, y1)

    def _shade(self, normal: FloatArray) -> float:
        light = self.lighting
        if light.ambient >= 1.0:
            return 1.0
        d = np.asarray(light.light_direction, dtype=np.float64)
        d = d / np.linalg.norm(d)
        return float(light.ambient + (1.0 - light.ambient) * max(0.0, float(normal @ d)))

    def _vignette(self, amount: float) -> npt.NDArray[np.float32]:
        cached = self._vignette_cache
        if cached is not None and cached[0] == amount:
            return cached[1]
        yy, xx = np.mgrid[0 : self.height, 0 : self.width].astype(np.float32)
        cx, cy = self.model.matrix[0, 2], self.model.matrix[1, 2]
        r2 = ((xx - cx) ** 2 + (yy - cy) ** 2) / float(cx**2 + cy**2)
        table = (1.0 - amount * r2).astype(np.float32)
        self._vignette_cache = (amount, table)
        result: npt.NDArray[np.float32] = table
        return result


class PixelRays:
    """The normalised rays (x/z, y/z) through a camera's pixels' sub-samples: the
    distorted pixel grid's corners, interpolated, kept whole when the table fits."""

    def __init__(self, model: CameraModel, width: int, height: int, supersample: int) -> None:
        self.width, self.height, self.supersample = width, height, supersample
        # Normalised coordinates (x/z, y/z) of every pixel corner: pixel (r, c) spans
        # corners [r, r+1] x [c, c+1], i.e. pixel positions c - 0.5 .. c + 0.5.
        grid = np.stack(np.meshgrid(np.arange(width + 1) - 0.5, np.arange(height + 1) - 0.5), -1)
        # float32 is ample: 6e-8 relative error is 5e-5 px at f = 900 px.
        self._corners = model.normalize(grid.reshape(-1, 2)).reshape(grid.shape).astype(np.float32)
        s = supersample
        self._offsets = ((np.arange(s) + 0.5) / s).astype(np.float32)  # sub-sample centres
        self._ray_table: npt.NDArray[np.float32] | None = None

    def of(self, box: Box) -> npt.NDArray[np.float32]:
        """Normalised (x, y) of the sub-samples of ``box`` (rows of sub-samples, columns,
        2), a view of the whole frame's table where it is kept."""
        x0, y0, x1, y1 = box
        s = self.supersample
        if self._ray_table is None and 8 * self.width * self.height * s * s <= MAX_RAY_TABLE_BYTES:
            self._ray_table = self._interpolate((0, 0, self.width, self.height))
        if self._ray_table is not None:
            return self._ray_table[y0 * s : y1 * s, x0 * s : x1 * s]
        return self._interpolate(box)

    def _interpolate(self, box: Box) -> npt.NDArray[np.float32]:
        """Sub-sample rays of ``box`` by bilinear interpolation of the corner table
        (distortion is smooth on a one-pixel scale, so this is exact to far below a
        micro-pixel); the same arithmetic for a box as for the whole frame."""
        x0, y0, x1, y1 = box
        s = self.supersample
        c = self._corners
        c00, c01 = c[y0:y1, x0:x1], c[y0:y1, x0 + 1 : x1 + 1]
        c10, c11 = c[y0 + 1 : y1 + 1, x0:x1], c[y0 + 1 : y1 + 1, x0 + 1 : x1 + 1]
        a = self._offsets[None, None, None, :, None]  # along x
        b = self._offsets[None, :, None, None, None]  # along y
        top = c00[:, None, :, None] * (1 - a) + c01[:, None, :, None] * a
        bot = c10[:, None, :, None] * (1 - a) + c11[:, None, :, None] * a
        rays = (top * (1 - b) + bot * b).reshape((y1 - y0) * s, (x1 - x0) * s, 2)
        return cast(npt.NDArray[np.float32], rays)  # float32 throughout; the stubs widen


class NoiseBank:
    """Pixel noise for a ``width`` x ``height`` camera, drawn from a bank of normals."""

    def __init__(self, width: int, height: int, seed: int | None) -> None:
        self.width, self.height = width, height
        self._rng = np.random.default_rng(seed)
        self._bank: npt.NDArray[np.float32] | None = None

    def draw(self, height: int, width: int) -> tuple[npt.NDArray[np.float32], bool]:
        """(height, width) of N(0, 1) noise and whether to negate it: a random window of a
        bank of two full frames of normals, with a random sign, a quarter of the window's
        size redrawn at a random place of the bank each frame. Drawing a whole frame of
        normals costs ~12 ms; this costs ~2 ms for a full frame (less for a crop), and each
        pixel is still N(0, 1), nearly independent from frame to frame."""
        size = 2 * self.width * self.height
        if self._bank is None:
            self._bank = self._rng.standard_normal(size, dtype=np.float32)
        n = height * width
        chunk = n // 4
        start = int(self._rng.integers(0, size - chunk))
        self._bank[start : start + chunk] = self._rng.standard_normal(chunk, dtype=np.float32)
        offset = int(self._rng.integers(0, size - n))
        frame = self._bank[offset : offset + n].reshape(height, width)
        return frame, bool(self._rng.integers(0, 2))


def _unit_outline() -> FloatArray:
    """(36, 2) points along the edges of the unit square centred at 0: nine per side, so
    that a distorted edge's bulge stays inside the bounding box."""
    edge = np.linspace(-0.5, 0.5, 9)
    ones = np.full_like(edge, 0.5)
    return np.concatenate(
        [np.c_[edge, ones], np.c_[ones, -edge], np.c_[-edge, -ones], np.c_[-ones, edge]]
    )


_UNIT_OUTLINE = _unit_outline()


def _as_scene(scene: Scene | Sequence[SceneItem], background: float | None) -> Scene:
    if not isinstance(scene, Scene):
        return Scene(list(scene), 128.0 if background is None else background)
    if background is not None:
        return Scene(scene.items, background)
    return scene


def _pose_of(item: SceneItem) -> FloatArray:
    return item.T_camera_marker if isinstance(item, SceneMarker) else item.T_camera_plane


def _marker_cells(item: SceneMarker) -> int:
    from softarm.vision.dictionaries import get_dictionary

    return int(get_dictionary(item.dictionary).markerSize + 2)


def _overlap(a: Box, b: Box) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


_AFFINE_CACHE: dict[
    tuple[int, float, float], tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]
] = {}


def _affine(tex: npt.NDArray[np.float32], offset: float, gain: float) -> npt.NDArray[np.float32]:
    """``offset + gain * tex`` (float32) in a one-texel frame of zeros (no change), kept
    for the next frame of the same marker."""
    key = (id(tex), offset, gain)
    hit = _AFFINE_CACHE.get(key)
    if hit is not None and hit[0] is tex:
        return hit[1]
    out = np.zeros((tex.shape[0] + 2, tex.shape[1] + 2), np.float32)
    out[1:-1, 1:-1] = np.float32(offset) + np.float32(gain) * tex
    if len(_AFFINE_CACHE) > 64:
        _AFFINE_CACHE.clear()
    _AFFINE_CACHE[key] = (tex, out)
    return out


_PREMULT_CACHE: dict[int, tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]] = {}


def _premultiplied(tex: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    """Two-channel (reflectance, alpha=1) texture in a one-texel frame of (0, 0), the
    value cv2.remap also returns outside it."""
    key = id(tex)
    hit = _PREMULT_CACHE.get(key)
    if hit is not None and hit[0] is tex:
        return hit[1]
    out = np.zeros((tex.shape[0] + 2, tex.shape[1] + 2, 2), np.float32)
    out[1:-1, 1:-1, 0] = tex
    out[1:-1, 1:-1, 1] = 1.0
    if len(_PREMULT_CACHE) > 64:
        _PREMULT_CACHE.clear()
    _PREMULT_CACHE[key] = (tex, out)
    return out
