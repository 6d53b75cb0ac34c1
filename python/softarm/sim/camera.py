"""A synthetic pinhole camera with lens distortion that renders ArUco scenes.

Rendering is by inverse mapping, only inside each plane's projected bounding box: every
pixel is split into ``supersample``² sub-samples; each sub-sample's pixel position is
undistorted to a ray (from a per-camera table of normalised coordinates at pixel corners,
bilinearly interpolated), the ray is intersected with the plane (a homography, since the
plane is flat), and the texture is sampled there with ``cv2.remap``. Averaging the
sub-samples (box filter) gives anti-aliased edges; the texture resolution is chosen so that
one texel is about one sub-sample. Planes are drawn far to near (painter's algorithm);
back-facing planes are culled. Then optional Gaussian blur, then Gaussian noise.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError
from softarm.sim.markers import SceneMarker, TexturedPlane
from softarm.vision._checks import FloatArray
from softarm.vision.camera_model import CameraModel

SceneItem = SceneMarker | TexturedPlane


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
        self._rng = np.random.default_rng(seed)
        self._bank: npt.NDArray[np.float32] | None = None
        # Normalised coordinates (x/z, y/z) of every pixel corner: pixel (r, c) spans
        # corners [r, r+1] x [c, c+1], i.e. pixel positions c - 0.5 .. c + 0.5.
        grid = np.stack(
            np.meshgrid(np.arange(self.width + 1) - 0.5, np.arange(self.height + 1) - 0.5), -1
        )
        # float32 is ample: 6e-8 relative error is 5e-5 px at f = 900 px.
        self._corners = model.normalize(grid.reshape(-1, 2)).reshape(grid.shape).astype(np.float32)
        s = self.supersample
        self._offsets = ((np.arange(s) + 0.5) / s).astype(np.float32)  # sub-sample centres

    def render(
        self, scene: Scene | Sequence[SceneItem], background: float | None = None
    ) -> npt.NDArray[np.uint8]:
        """Render ``scene`` to a (height, width) uint8 gray image."""
        if not isinstance(scene, Scene):
            scene = Scene(list(scene), 128.0 if background is None else background)
        elif background is not None:
            scene = Scene(scene.items, background)
        img = np.full((self.height, self.width), scene.background, np.float32)
        items = sorted(scene.items, key=lambda it: -float(np.linalg.norm(_pose_of(it)[:3, 3])))
        for item in items:
            self._draw(img, item)
        light = self.lighting
        if light.vignetting > 0:
            img *= self._vignette(light.vignetting)
        if self.blur > 0:
            img = np.asarray(cv2.GaussianBlur(img, (0, 0), self.blur), dtype=np.float32)
        if self.noise_std > 0:
            img += np.float32(self.noise_std) * self._noise()
        np.maximum(img, 0.0, out=img)
        # Rounds to nearest and saturates at 255 (values are >= 0 here, so abs is a no-op).
        return np.asarray(cv2.convertScaleAbs(img), dtype=np.uint8)

    def _draw(self, img: npt.NDArray[np.float32], item: SceneItem) -> None:
        pose = _pose_of(item)
        rot, t = pose[:3, :3], pose[:3, 3]
        normal = rot[:, 2]
        if float(normal @ t) >= 0.0:  # back face: the camera is behind the plane
            return
        if isinstance(item, SceneMarker):
            cells = item.marker_length / (_marker_cells(item) or 1)
            z_near = max(float(t[2]) - item.marker_length, 1e-3)
            px_per_cell = self.model.focal * cells / z_near
            item = item.to_plane(int(np.ceil(self.supersample * px_per_cell)))
        box = self._bbox(item)
        if box is None:
            return
        x0, y0, x1, y1 = box
        s = self.supersample
        # Sub-sample rays by bilinear interpolation of the corner table (distortion is
        # smooth on a one-pixel scale, so this is exact to far below a micro-pixel).
        c = self._corners
        c00, c01 = c[y0:y1, x0:x1], c[y0:y1, x0 + 1 : x1 + 1]
        c10, c11 = c[y0 + 1 : y1 + 1, x0:x1], c[y0 + 1 : y1 + 1, x0 + 1 : x1 + 1]
        a = self._offsets[None, None, None, :, None]  # along x
        b = self._offsets[None, :, None, None, None]  # along y
        top = c00[:, None, :, None] * (1 - a) + c01[:, None, :, None] * a
        bot = c10[:, None, :, None] * (1 - a) + c11[:, None, :, None] * a
        rays = (top * (1 - b) + bot * b).reshape((y1 - y0) * s, (x1 - x0) * s, 2)
        # Ray-plane intersection as a homography: (u, v, 1) ∝ [r1 r2 t]⁻¹ (x, y, 1).
        hinv = np.linalg.inv(np.column_stack([rot[:, 0], rot[:, 1], t]))
        tex = item.texture
        th, tw = tex.shape
        # Fold the metric-to-texel map (texel centres at integer map coordinates, the
        # cv2.remap convention) into the homography: one projective map, float32.
        to_tex = np.array(
            [
                [tw / item.width, 0.0, 0.5 * tw - 0.5],
                [0.0, -th / item.height, 0.5 * th - 0.5],
                [0, 0, 1],
            ]
        )
        hom = (to_tex @ hinv).astype(np.float32)
        x, y = rays[..., 0], rays[..., 1]
        den = hom[2, 0] * x + hom[2, 1] * y + hom[2, 2]
        behind = den <= 1e-12  # rays that miss the plane (it lies behind the camera)
        den[behind] = 1.0
        np.reciprocal(den, out=den)
        mx = (hom[0, 0] * x + hom[0, 1] * y + hom[0, 2]) * den
        my = (hom[1, 0] * x + hom[1, 1] * y + hom[1, 2]) * den
        mx[behind] = -10.0
        rgba = _premultiplied(tex)
        sampled = cv2.remap(rgba, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
        small = cv2.resize(sampled, (x1 - x0, y1 - y0), interpolation=cv2.INTER_AREA)
        refl, alpha = small[..., 0], small[..., 1]
        shade = self._shade(normal)
        light = self.lighting
        ink = shade * light.black
        color = ink * alpha + shade * (light.white - light.black) * refl
        region = img[y0:y1, x0:x1]
        region *= 1.0 - alpha
        region += color

    def _noise(self) -> npt.NDArray[np.float32]:
        """A frame of N(0, 1) noise: a random window of a bank of two frames of normals,
        with a random sign, an eighth of the bank redrawn each frame. Drawing a whole
        frame of normals costs ~12 ms; this costs ~2 ms and each pixel is still N(0, 1),
        nearly independent from frame to frame."""
        n = self.width * self.height
        if self._bank is None:
            self._bank = self._rng.standard_normal(2 * n, dtype=np.float32)
        chunk = n // 4
        start = int(self._rng.integers(0, 2 * n - chunk))
        self._bank[start : start + chunk] = self._rng.standard_normal(chunk, dtype=np.float32)
        offset = int(self._rng.integers(0, n))
        frame = self._bank[offset : offset + n].reshape(self.height, self.width)
        return -frame if self._rng.integers(0, 2) else frame

    def _bbox(self, plane: TexturedPlane) -> tuple[int, int, int, int] | None:
        """Pixel bounding box [x0, x1) x [y0, y1) of the plane's projection, or None."""
        edge = np.linspace(-0.5, 0.5, 9)
        ones = np.full_like(edge, 0.5)
        outline = np.concatenate(
            [np.c_[edge, ones], np.c_[ones, -edge], np.c_[-edge, -ones], np.c_[-ones, edge]]
        ) * [plane.width, plane.height]
        pose = plane.T_camera_plane
        pts = outline @ pose[:3, :2].T + pose[:3, 3]
        if np.any(pts[:, 2] <= 1e-3):
            return None  # straddles the camera plane: not drawn (documented limitation)
        pix = self.model.project(pts)
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
        yy, xx = np.mgrid[0 : self.height, 0 : self.width].astype(np.float32)
        cx, cy = self.model.matrix[0, 2], self.model.matrix[1, 2]
        r2 = ((xx - cx) ** 2 + (yy - cy) ** 2) / float(cx**2 + cy**2)
        return (1.0 - amount * r2).astype(np.float32)


def _pose_of(item: SceneItem) -> FloatArray:
    return item.T_camera_marker if isinstance(item, SceneMarker) else item.T_camera_plane


def _marker_cells(item: SceneMarker) -> int:
    from softarm.vision.dictionaries import get_dictionary

    return int(get_dictionary(item.dictionary).markerSize + 2)


_PREMULT_CACHE: dict[int, tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]] = {}


def _premultiplied(tex: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    """Two-channel (reflectance, alpha=1) texture; outside it cv2.remap returns (0, 0)."""
    key = id(tex)
    hit = _PREMULT_CACHE.get(key)
    if hit is not None and hit[0] is tex:
        return hit[1]
    out = np.dstack([tex, np.ones_like(tex)])
    if len(_PREMULT_CACHE) > 64:
        _PREMULT_CACHE.clear()
    _PREMULT_CACHE[key] = (tex, out)
    return out
