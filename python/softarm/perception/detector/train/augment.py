"""Augmentation of training crops, deterministic in the random generator it is given: scale
(times the sample's own ``zoom``), crop (most of them centred near a fruit), mirror,
then colour (white balance, hue, saturation), exposure and gamma, blur (Gaussian or
motion), sensor noise, JPEG compression and cut-outs (a rectangle of flat colour hides
what is under it, which the labels then call background)."""

from __future__ import annotations

from typing import Any, cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.perception.detector.train.samples import IGNORE, Sample, stages

__all__ = ["CROP", "crop_batch"]

#: Side (px) of the square training crops of a plain network (a stem network's are twice
#: this, so that its half-resolution layers see the same CROP × CROP).
CROP = 128
#: Log-uniform range of the scale applied before cropping, by default (the renders' own
#: scale is the network's input scale; a network run on images larger than its training
#: renders is trained on a range shifted up, ``TrainSettings.scale``).
SCALE = (0.6, 1.7)
#: Share of crops centred on a fruit pixel (else anywhere).
ON_FRUIT = 0.7
_U8 = npt.NDArray[np.uint8]
_F32 = npt.NDArray[np.float32]


#: A crop: image, classes, centre heatmap and the distance target (None without it).
Crop = tuple[_U8, _U8, _F32, _F32 | None]


def _scaled(s: Sample, rng: np.random.Generator, scale: tuple[float, float]) -> Crop:
    f = float(np.exp(rng.uniform(np.log(scale[0]), np.log(scale[1])))) * s.zoom
    h, w = s.classes.shape
    size = (max(CROP // 4, round(w * f)), max(CROP // 4, round(h * f)))
    mode = cv2.INTER_AREA if f < 1 else cv2.INTER_LINEAR
    image = cast(_U8, cv2.resize(s.image, size, interpolation=mode))
    classes = cast(_U8, cv2.resize(s.classes, size, interpolation=cv2.INTER_NEAREST))
    centres = cast(_F32, cv2.resize(s.centres, size, interpolation=cv2.INTER_LINEAR))
    distance = None
    if s.distance is not None:
        distance = cast(_F32, cv2.resize(s.distance, size, interpolation=cv2.INTER_LINEAR))
    return image, classes, centres, distance


def _padded(values: npt.NDArray[Any], pad_y: int, pad_x: int, fill: int) -> npt.NDArray[Any]:
    return cast(
        npt.NDArray[Any],
        cv2.copyMakeBorder(values, 0, pad_y, 0, pad_x, cv2.BORDER_CONSTANT, value=fill),
    )


def _crop(s: Sample, rng: np.random.Generator, scale: tuple[float, float], crop: int) -> Crop:
    image, classes, centres, distance = _scaled(s, rng, scale)
    h, w = classes.shape
    pad_y, pad_x = max(0, crop - h), max(0, crop - w)
    if pad_y or pad_x:
        image = _padded(image, pad_y, pad_x, 0)
        classes = _padded(classes, pad_y, pad_x, IGNORE)
        centres = _padded(centres, pad_y, pad_x, 0)
        distance = None if distance is None else _padded(distance, pad_y, pad_x, 0)
        h, w = classes.shape
    plain = stages(classes)  # a boundary pixel is fruit too
    fruit = np.flatnonzero((plain >= 1) & (plain <= 3))
    if fruit.size and rng.uniform() < ON_FRUIT:
        cy, cx = divmod(int(fruit[rng.integers(fruit.size)]), w)
        y0 = int(np.clip(cy - crop // 2 + rng.integers(-crop // 4, crop // 4 + 1), 0, h - crop))
        x0 = int(np.clip(cx - crop // 2 + rng.integers(-crop // 4, crop // 4 + 1), 0, w - crop))
    else:
        y0, x0 = int(rng.integers(h - crop + 1)), int(rng.integers(w - crop + 1))
    window = np.s_[y0 : y0 + crop, x0 : x0 + crop]
    mirror = rng.uniform() < 0.5
    step = -1 if mirror else 1

    def cut(values: npt.NDArray[Any]) -> npt.NDArray[Any]:
        return np.ascontiguousarray(values[window][:, ::step])

    return cut(image), cut(classes), cut(centres), None if distance is None else cut(distance)


def _colour(image: _U8, rng: np.random.Generator) -> _U8:
    hsv = cv2.cvtColor(image, cv2.COLOR_BGR2HSV).astype(np.float32)
    hsv[..., 0] = (hsv[..., 0] + rng.uniform(-6, 6)) % 180
    hsv[..., 1] *= rng.uniform(0.7, 1.3)
    out = cv2.cvtColor(np.clip(hsv, 0, 255).astype(np.uint8), cv2.COLOR_HSV2BGR)
    x = out.astype(np.float32) / 255.0
    x *= rng.uniform(0.85, 1.15, 3).astype(np.float32)  # white balance
    x *= float(np.exp(rng.uniform(np.log(0.5), np.log(1.7))))  # exposure, clipping in sun
    x = np.clip(x, 0.0, 1.0) ** float(rng.uniform(0.75, 1.35))
    return cast(_U8, (x * 255.0 + 0.5).astype(np.uint8))


def _blur(image: _U8, rng: np.random.Generator) -> _U8:
    u = rng.uniform()
    if u < 0.25:
        return cast(_U8, cv2.GaussianBlur(image, (0, 0), float(rng.uniform(0.4, 1.3))))
    if u < 0.4:
        n = int(rng.integers(3, 8))
        kernel = np.zeros((n, n), np.float32)
        kernel[n // 2] = 1.0 / n
        rot = cv2.getRotationMatrix2D(((n - 1) / 2, (n - 1) / 2), float(rng.uniform(0, 180)), 1.0)
        kernel = cast(_F32, cv2.warpAffine(kernel, rot, (n, n)))
        return cast(_U8, cv2.filter2D(image, -1, kernel / max(float(kernel.sum()), 1e-6)))
    return image


def _sensor(image: _U8, rng: np.random.Generator) -> _U8:
    sigma = rng.uniform(0.0, 8.0)
    noisy = image.astype(np.float32) + rng.normal(0.0, sigma, image.shape).astype(np.float32)
    out = cast(_U8, np.clip(noisy, 0, 255).astype(np.uint8))
    if rng.uniform() < 0.5:
        quality = int(rng.integers(30, 91))
        ok, buf = cv2.imencode(".jpg", out, [cv2.IMWRITE_JPEG_QUALITY, quality])
        if ok:
            out = cast(_U8, cv2.imdecode(buf, cv2.IMREAD_COLOR))
    return out


def _cut_outs(
    image: _U8, classes: _U8, centres: _F32, distance: _F32 | None, rng: np.random.Generator
) -> None:
    if rng.uniform() >= 0.4:
        return
    crop = classes.shape[0]
    for _ in range(int(rng.integers(1, 4))):
        hh, ww = (int(v) * crop // CROP for v in rng.integers(8, 41, 2))
        y, x = int(rng.integers(0, crop - hh + 1)), int(rng.integers(0, crop - ww + 1))
        image[y : y + hh, x : x + ww] = rng.integers(0, 256, 3).astype(np.uint8)
        classes[y : y + hh, x : x + ww] = 0
        centres[y : y + hh, x : x + ww] = 0.0
        if distance is not None:
            distance[y : y + hh, x : x + ww] = 0.0


def augmented(
    s: Sample, rng: np.random.Generator, scale: tuple[float, float] = SCALE, crop: int = CROP
) -> Crop:
    """One augmented ``crop`` × ``crop`` (image, classes, centres, distance target or None)
    of ``s``, scaled by a factor drawn log-uniformly from ``scale`` times the sample's
    ``zoom``."""
    image, classes, centres, distance = _crop(s, rng, scale, crop)
    image = _sensor(_blur(_colour(image, rng), rng), rng)
    image, classes, centres = image.copy(), classes.copy(), centres.copy()
    distance = None if distance is None else distance.copy()
    _cut_outs(image, classes, centres, distance, rng)
    return image, classes, centres, distance


def crop_batch(
    samples: list[Sample],
    indices: npt.NDArray[np.int64],
    seed: int,
    step: int,
    scale: tuple[float, float] = SCALE,
    crop: int = CROP,
) -> tuple[_U8, _U8, _F32, _F32]:
    """A batch of augmented crops of ``samples[indices]``, the same for the same
    ``seed``, ``step``, ``scale`` and ``crop``: (N, crop, crop, 3), (N, crop, crop),
    (N, crop, crop) and the distance targets (N, crop, crop), zero for a sample without
    one."""
    out = [
        augmented(samples[int(i)], np.random.default_rng([seed, step, k]), scale, crop)
        for k, i in enumerate(indices)
    ]
    distance = [np.zeros_like(o[2]) if o[3] is None else o[3] for o in out]
    return (
        np.stack([o[0] for o in out]), np.stack([o[1] for o in out]),
        np.stack([o[2] for o in out]), np.stack(distance),
    )  # fmt: skip
