"""What a real camera does to a rendered frame: motion blur, vignetting, white balance,
exposure (auto or fixed, clipping at full well, crushed blacks), shot and read noise,
8-bit quantisation and lossy (JPEG) compression; and the small differences between the
two eyes of a stereo pair (exposure, a sub-pixel rectification error).

The renderer's 8-bit output is taken as the scene's radiance on a linear scale (0-255
DN at an exposure of 1). The steps run in a sensor's order: the optics and the motion
(blur, vignetting) act on the light, the colour filter and exposure on the charge,
the noise on the read-out, compression last. Every random draw comes from the
generator given, so a frame is a function of its seed.

Noise model (in DN, after exposure): a pixel of mean signal ``s`` has variance
``gain * s + read_noise**2`` (shot noise, Poisson in electrons, ``gain`` DN per
electron, plus the read-out's Gaussian noise), drawn as a Gaussian of that variance;
then the signal is clipped to [0, ``full_well``] DN (saturation in the sun, nothing
below black in the shade) and rounded.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError
from softarm.sim.render.motion_blur import check_flow, flow_blur

__all__ = ["CameraEffects", "StereoEffects", "blur_kernel"]

#: What auto-exposure aims the frame's mean luminance at (DN), and how far it may go;
#: it keeps the brightest AUTO_HIGHLIGHT_SHARE of the pixels at or under
#: AUTO_HIGHLIGHT_DN (a camera's metering keeps a bright subject, a sunlit marker, from
#: clipping because the rest of the frame is dark), but gives up at most
#: AUTO_HIGHLIGHT_GIVE of the mean's exposure for it (a sky in the frame still clips
#: rather than the whole frame going dark).
AUTO_TARGET_DN = 110.0
AUTO_RANGE = (0.25, 8.0)
AUTO_HIGHLIGHT_SHARE = 0.005
AUTO_HIGHLIGHT_DN = 230.0
AUTO_HIGHLIGHT_GIVE = 0.5


def blur_kernel(velocity_px: tuple[float, float], exposure_s: float) -> npt.NDArray[np.float64]:
    """A linear motion-blur kernel: the image moving ``velocity_px`` (vx, vy) px/s for
    ``exposure_s`` s smears each point along a segment of that length; the kernel is
    that segment drawn with sub-pixel weights, normalised to sum to 1 (blur moves no
    light). Shorter than a pixel: the identity (1, 1) kernel."""
    vx, vy = (float(v) * exposure_s for v in velocity_px)
    length = float(np.hypot(vx, vy))
    if not np.isfinite(length):
        raise ParameterError(f"velocity_px must be finite, got {velocity_px}")
    if length < 1.0:
        return np.ones((1, 1))
    half = int(np.ceil(length / 2.0)) + 1
    size = 2 * half + 1
    kernel = np.zeros((size, size))
    steps = max(int(np.ceil(4 * length)), 2)
    for t in np.linspace(-0.5, 0.5, steps):
        x, y = half + t * vx, half + t * vy
        x0, y0 = int(np.floor(x)), int(np.floor(y))
        fx, fy = x - x0, y - y0  # bilinear splat of each sample
        kernel[y0, x0] += (1 - fx) * (1 - fy)
        kernel[y0, x0 + 1] += fx * (1 - fy)
        kernel[y0 + 1, x0] += (1 - fx) * fy
        kernel[y0 + 1, x0 + 1] += fx * fy
    result: npt.NDArray[np.float64] = kernel / kernel.sum()
    return result


@dataclass(frozen=True)
class CameraEffects:
    """One camera's sensor and optics (see the module docstring).

    Args:
        exposure: the exposure gain over the render; None: auto-exposure, the frame's
            mean luminance brought to AUTO_TARGET_DN, its brightest pixels kept under
            AUTO_HIGHLIGHT_DN at the cost of up to half of that, within AUTO_RANGE.
        exposure_bias: a factor on the exposure (auto or fixed): one eye of a pair
            exposing a little differently, or an auto-exposure that over- or
            under-shoots.
        white_balance: (b, g, r) gains of the camera's white balance error.
        gain: DN per electron (the shot noise's scale); 0: no shot noise.
        read_noise: the read-out noise's standard deviation (DN).
        full_well: the saturation level (DN): the sun clips here.
        black_level: DN subtracted before clipping at 0: crushed blacks in shade.
        vignetting: the light lost at the image corners (0: none; 0.4: the corners get
            60 %), falling off as the squared radius.
        exposure_s: the exposure time (s), over which motion blurs.
        jpeg_quality: the JPEG quality the frame is delivered at (None: lossless).
    """

    exposure: float | None = None
    exposure_bias: float = 1.0
    white_balance: tuple[float, float, float] = (1.0, 1.0, 1.0)
    gain: float = 0.0
    read_noise: float = 0.0
    full_well: float = 255.0
    black_level: float = 0.0
    vignetting: float = 0.0
    exposure_s: float = 0.01
    jpeg_quality: int | None = None

    def __post_init__(self) -> None:
        checks = {
            "exposure_bias": self.exposure_bias > 0,
            "gain": self.gain >= 0,
            "read_noise": self.read_noise >= 0,
            "full_well": 0 < self.full_well <= 255,
            "black_level": 0 <= self.black_level < self.full_well,
            "vignetting": 0 <= self.vignetting < 1,
            "exposure_s": self.exposure_s >= 0,
            "white_balance": all(w > 0 for w in self.white_balance),
        }
        if self.exposure is not None:
            checks["exposure"] = self.exposure > 0
        if self.jpeg_quality is not None:
            checks["jpeg_quality"] = 1 <= self.jpeg_quality <= 100
        bad = [name for name, ok in checks.items() if not ok]
        if bad:
            raise ParameterError(f"CameraEffects: {bad[0]} out of range ({self!r})")

    def exposure_of(self, image: npt.NDArray[np.uint8]) -> float:
        """The exposure this camera gives ``image``: the fixed one, or auto-exposure's
        (its mean luminance to AUTO_TARGET_DN, its highlights kept under
        AUTO_HIGHLIGHT_DN), times the bias."""
        if self.exposure is not None:
            return self.exposure * self.exposure_bias
        grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        mean = float(cv2.mean(grey)[0])
        highlight = _highlight(image)
        by_mean = AUTO_TARGET_DN / max(mean, 1e-3)
        by_highlight = AUTO_HIGHLIGHT_DN / max(highlight, 1)
        auto = max(min(by_mean, by_highlight), (1 - AUTO_HIGHLIGHT_GIVE) * by_mean)
        return float(np.clip(auto, *AUTO_RANGE)) * self.exposure_bias

    def roi_exposure_of(self, roi: npt.NDArray[np.uint8], scale: float = 1.0) -> float:
        """The exposure a camera metering on a region of interest gives ``roi``'s
        pixels: the ROI's brightest AUTO_HIGHLIGHT_SHARE brought to AUTO_HIGHLIGHT_DN,
        nothing given up for a mean (the ROI is the subject: a marker's white paper
        must not clip, whatever the rest of the frame), within AUTO_RANGE, times the
        bias; the fixed exposure when there is one. ``scale``: the share of the scene's
        light ``roi`` was rendered with (0.5: at half the light, so that what is
        brighter than 255 DN at an exposure of 1 is not clipped by the render); the
        exposure returned is for ``roi``'s pixels, AUTO_RANGE for the scene's."""
        if not 0 < scale <= 1:
            raise ParameterError(f"scale must be in (0, 1], got {scale}")
        if self.exposure is not None:
            return self.exposure * self.exposure_bias / scale
        by_highlight = scale * AUTO_HIGHLIGHT_DN / max(_highlight(roi), 1)
        return float(np.clip(by_highlight, *AUTO_RANGE)) * self.exposure_bias / scale

    def apply(
        self,
        image: npt.NDArray[np.uint8],
        rng: np.random.Generator,
        velocity_px: tuple[float, float] = (0.0, 0.0),
        exposure: float | None = None,
        offset_px: tuple[float, float] = (0.0, 0.0),
        flow_px_s: npt.NDArray[np.float32] | None = None,
        still: npt.NDArray[np.bool_] | None = None,
    ) -> npt.NDArray[np.uint8]:
        """``image`` (H, W, 3) BGR uint8 as this camera delivers it. ``velocity_px``: the
        image's motion (px/s) during the exposure, the same everywhere; ``exposure``:
        the gain to use (a window of a frame keeps its frame's auto-exposure), None:
        :meth:`exposure_of`; ``offset_px``: a shift of the image (a rectification
        error); ``flow_px_s``: (H, W, 2) each pixel's own motion (px/s) during the
        exposure (:mod:`softarm.sim.render.motion_blur`), before ``velocity_px``'s;
        ``still``: (H, W) pixels that move with the camera (no blur, nor light lent)."""
        if image.ndim != 3 or image.shape[2] != 3:
            raise ParameterError(f"image must be (H, W, 3), got {image.shape}")
        gain = self.exposure_of(image) if exposure is None else exposure
        light = image.astype(np.float32)
        if offset_px != (0.0, 0.0):
            light = _shifted(light, offset_px)
        if flow_px_s is not None:
            flow = check_flow(flow_px_s, image.shape)
            if still is not None and np.shape(still) != image.shape[:2]:
                raise ParameterError(f"still must be {image.shape[:2]}, got {np.shape(still)}")
            light = flow_blur(light, flow * np.float32(self.exposure_s), still)
        kernel = blur_kernel(velocity_px, self.exposure_s)
        if kernel.size > 1:
            light = cast(
                npt.NDArray[np.float32],
                cv2.filter2D(light, -1, kernel.astype(np.float32),
                             borderType=cv2.BORDER_REPLICATE),
            )  # fmt: skip
        if self.vignetting:
            light *= _falloff(image.shape[:2], self.vignetting)[..., None]
        light *= np.asarray(self.white_balance, np.float32) * np.float32(gain)
        signal = self.sensor(light, rng)
        if self.jpeg_quality is None:
            return signal
        ok, data = cv2.imencode(".jpg", signal, [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality])
        if not ok:
            return signal
        return cast(npt.NDArray[np.uint8], cv2.imdecode(data, cv2.IMREAD_COLOR))

    def sensor(
        self, light: npt.NDArray[np.float32], rng: np.random.Generator
    ) -> npt.NDArray[np.uint8]:
        """The read-out of ``light`` (DN, float): shot and read noise, black level,
        clipping at 0 and ``full_well``, rounding to 8 bits."""
        out = np.maximum(light, 0.0)
        dt = out.dtype.type  # the scalars as the arithmetic would cast them
        if self.gain or self.read_noise:
            # In place, each step the same float32 operation as written out in full
            # (std = sqrt(gain * out + read_noise**2); out += std * noise): the same
            # values without four frame-sized temporaries.
            std = np.multiply(out, dt(self.gain))
            std += dt(self.read_noise**2)
            np.sqrt(std, out=std)
            noise = np.empty(light.shape, np.float32)
            # OpenCV's generator is several times faster than numpy's on a full frame;
            # it is seeded from ``rng``, so the frame stays a function of the seed.
            cv2.setRNGSeed(int(rng.integers(2**31)))
            cv2.randn(noise.reshape(light.shape[0], -1), 0.0, 1.0)  # type: ignore[call-overload]
            std *= noise
            out += std
        if self.black_level:
            out -= np.float32(self.black_level)
        np.clip(out, 0.0, self.full_well, out=out)
        out += np.float32(0.5)
        result: npt.NDArray[np.uint8] = out.astype(np.uint8)
        return result


@dataclass(frozen=True)
class StereoEffects:
    """The two eyes of a stereo pair: the left's :class:`CameraEffects`, the right's
    exposure relative to the left's (``right_exposure``), and the right image's
    rectification error ``right_offset_px`` (dx, dy): the residual a calibration leaves,
    a few tenths of a pixel. The right eye exposes with the left's exposure times
    ``right_exposure`` (a ZED2 meters once for both)."""

    left: CameraEffects
    right_exposure: float = 1.0
    right_offset_px: tuple[float, float] = (0.0, 0.0)

    def right(self) -> CameraEffects:
        """The right eye's effects (its exposure bias folded in)."""
        return replace(self.left, exposure_bias=self.left.exposure_bias * self.right_exposure)


def _highlight(image: npt.NDArray[np.uint8]) -> int:
    """The grey level (DN) at or above which the brightest AUTO_HIGHLIGHT_SHARE of
    ``image``'s (BGR) pixels lie."""
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    counts = cv2.calcHist([grey], [0], None, [256], [0, 256]).ravel()
    above = np.cumsum(counts[::-1])  # pixels at or above each level, from 255 down
    return 255 - int(np.searchsorted(above, AUTO_HIGHLIGHT_SHARE * grey.size))


@functools.lru_cache(maxsize=8)
def _falloff(shape: tuple[int, ...], strength: float) -> npt.NDArray[np.float32]:
    """1 at the image centre, 1 - ``strength`` at its corners, quadratic in radius."""
    h, w = shape
    y, x = np.ogrid[:h, :w]
    r2 = ((x - (w - 1) / 2) ** 2 + (y - (h - 1) / 2) ** 2) / (
        ((w - 1) / 2) ** 2 + ((h - 1) / 2) ** 2
    )
    result: npt.NDArray[np.float32] = (1.0 - strength * r2).astype(np.float32)
    return result


def _shifted(
    image: npt.NDArray[np.float32], offset: tuple[float, float]
) -> npt.NDArray[np.float32]:
    """``image`` moved by ``offset`` (dx, dy) px, bilinear, edges repeated."""
    h, w = image.shape[:2]
    M = np.array([[1.0, 0.0, offset[0]], [0.0, 1.0, offset[1]]], np.float32)
    out = cv2.warpAffine(image, M, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return cast(npt.NDArray[np.float32], out)  # warpAffine keeps the dtype
