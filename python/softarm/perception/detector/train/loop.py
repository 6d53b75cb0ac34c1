"""The training loop (JAX + optax): class-weighted cross-entropy over the pixels' classes
plus a weighted logistic loss on the centre heatmap (or CenterNet's focal loss:
:mod:`.focal`), AdamW with a cosine schedule, on
batches of augmented crops (twice the side for a network with the stride-2 stem, whose
outputs are scored against the labels at half resolution); deterministic in the seed
(the same crops, the same order, the same initial weights). With the boundary class,
its own output is trained by a logistic loss whose boundary pixels weigh BOUNDARY_WEIGHT
(a fruit class's weight) and every other pixel 1. With the distance target (each fruit
pixel's distance to its own fruit's edge over that fruit's largest: ``distance_target``),
its output (the last) is trained by a logistic loss against that soft target over the
fruit pixels alone (off fruit the decoding never reads it). JAX runs on a GPU where it
sees one, else on the CPU."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
import numpy.typing as npt
import optax

from softarm.perception.detector.network import CLASSES, normalise
from softarm.perception.detector.train.augment import CROP, SCALE, crop_batch
from softarm.perception.detector.train.focal import focal_loss, prior_bias, sharpened
from softarm.perception.detector.train.samples import BOUNDARY_FLAG, IGNORE, Sample
from softarm.perception.detector.train.unet import WIDTHS, Params, apply, init_params

__all__ = ["CLASS_WEIGHTS", "TrainSettings", "fit"]

#: Loss weight of each class's pixels (fruit and canes are few pixels of a frame).
CLASS_WEIGHTS = (1.0, 2.5, 3.0, 2.5, 1.5)
#: Weight of the centre heatmap's loss, and how much more a peak's pixels count.
CENTRE_WEIGHT = 1.0
CENTRE_POSITIVE = 20.0
#: Loss weight of a boundary pixel in the boundary class's loss (every other pixel weighs
#: 1). The boundary is about 2 % of the fruit pixels, 0.06 % of all: at the ripe class's
#: 2.5, a 40-epoch run's boundary probability stayed under 0.4 everywhere on the
#: validation renders (dataset seed 100300), so that nothing was ever cut; at 10 a pixel
#: is called boundary once about one in eleven such pixels is.
BOUNDARY_WEIGHT = 10.0
#: Weight of the distance target's loss (a mean over fruit pixels, as the class loss is
#: a weighted mean over all).
DISTANCE_WEIGHT = 1.0


@dataclass(frozen=True)
class TrainSettings:
    """Epochs (one crop of every image each), batch size, peak learning rate, seed, the
    network's channel widths, the augmentation's scale range, whether the network
    has the stride-2 stem (``unet``) and the heatmap's loss (of ``network.HEATMAPS``:
    the weighted logistic loss, the default, or CenterNet's penalty-reduced focal loss,
    :mod:`.focal`, whose peaks are sharp, one per fruit) and whether the network has the
    boundary class (``boundary``: the pixels of a fruit against another's) and the
    normalised distance to each fruit's edge (``distance``)."""

    epochs: int = 150
    batch: int = 12
    learning_rate: float = 3e-3
    seed: int = 0
    widths: tuple[int, ...] = WIDTHS
    scale: tuple[float, float] = SCALE
    stem: bool = False
    heatmap: str = "logistic"
    boundary: bool = False
    distance: bool = False
    losses: list[float] = field(default_factory=list, compare=False)


def _boundary_loss(logit: Any, classes: Any, valid: Any) -> Any:
    """The boundary class's weighted logistic loss (its pixels carry BOUNDARY_FLAG)."""
    target = valid & ((classes & BOUNDARY_FLAG) > 0)
    bce = optax.sigmoid_binary_cross_entropy(logit, target.astype(jnp.float32))
    w = jnp.where(target, BOUNDARY_WEIGHT, 1.0) * valid
    return jnp.sum(bce * w) / jnp.maximum(jnp.sum(w), 1.0)


def _distance_loss(logit: Any, target: Any, stage: Any, valid: Any) -> Any:
    """The distance output's logistic loss against its soft target, over fruit pixels."""
    fruit = (valid & (stage >= 1) & (stage <= 3)).astype(jnp.float32)
    bce = optax.sigmoid_binary_cross_entropy(logit, target)
    return jnp.sum(bce * fruit) / jnp.maximum(jnp.sum(fruit), 1.0)


def _loss(
    params: Params,
    x: Any,
    classes: Any,
    centres: Any,
    distance: Any,
    flags: tuple[bool, bool, bool] = (False, False, False),
) -> Any:
    """The training loss of a batch; ``flags``: (focal heatmap, boundary class, distance
    target)."""
    focal, edge, dist = flags
    out = apply(params, x)
    logits, centre = out[..., : len(CLASSES)], out[..., len(CLASSES)]
    valid = classes != IGNORE
    target = jnp.where(valid, classes & (BOUNDARY_FLAG - 1), 0)  # the stage, flag dropped
    ce = optax.softmax_cross_entropy_with_integer_labels(logits, target)
    w = jnp.asarray(CLASS_WEIGHTS)[target] * valid
    loss = jnp.sum(ce * w) / jnp.maximum(jnp.sum(w), 1.0)
    if edge:
        loss = loss + _boundary_loss(out[..., len(CLASSES) + 1], classes, valid)
    if dist:
        loss = loss + DISTANCE_WEIGHT * _distance_loss(out[..., -1], distance, target, valid)
    if focal:
        return loss + CENTRE_WEIGHT * focal_loss(centre, centres)
    bce = optax.sigmoid_binary_cross_entropy(centre, centres)
    cw = 1.0 + CENTRE_POSITIVE * centres
    centre_loss = jnp.sum(bce * cw) / jnp.sum(cw)
    return loss + CENTRE_WEIGHT * centre_loss


def _halved(
    classes: npt.NDArray[np.uint8],
    centres: npt.NDArray[np.float32],
    distance: npt.NDArray[np.float32],
) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """The labels of a batch at a stem network's output resolution: each 2×2 block's
    top-left class and distance (the output pixel's, as the image shrinks for a plain
    network) and the block's mean heatmap."""
    n, h, w = centres.shape
    mean = centres.reshape(n, h // 2, 2, w // 2, 2).mean(axis=(2, 4))
    return (
        np.ascontiguousarray(classes[:, ::2, ::2]), mean.astype(np.float32),
        np.ascontiguousarray(distance[:, ::2, ::2]),
    )  # fmt: skip


def fit(
    samples: list[Sample],
    settings: TrainSettings,
    params: Params | None = None,
    on_epoch: Callable[[int, float, float], None] = lambda e, loss, s: None,
) -> Params:
    """Train from ``params`` (default: fresh, from the seed) on ``samples``; calls
    ``on_epoch(epoch, mean loss, seconds)`` after each epoch."""
    focal = settings.heatmap == "focal"
    if params is None:
        params = init_params(
            settings.seed, settings.widths, settings.stem, settings.boundary, settings.distance
        )
        if focal:  # the heatmap starts at PRIOR everywhere, as CenterNet's
            w, b = params["head"]
            params = {**params, "head": (w, b.at[len(CLASSES)].set(prior_bias()))}
    crop = CROP * 2 if settings.stem else CROP
    per_epoch = max(1, int(np.ceil(len(samples) / settings.batch)))
    total = settings.epochs * per_epoch
    schedule = optax.warmup_cosine_decay_schedule(
        0.0, settings.learning_rate, min(50, max(1, total // 10)), max(total, 2)
    )
    optimiser = optax.adamw(schedule, weight_decay=1e-4)
    state = optimiser.init(params)

    @jax.jit
    def step(p: Params, s: Any, x: Any, c: Any, h: Any, d: Any) -> tuple[Params, Any, Any]:
        flags = (focal, settings.boundary, settings.distance)
        loss, grads = jax.value_and_grad(_loss)(p, x, c, h, d, flags)
        updates, s = optimiser.update(grads, s, p)
        return optax.apply_updates(p, updates), s, loss

    order_rng = np.random.default_rng([settings.seed, 1])
    n = 0
    for epoch in range(settings.epochs):
        start = time.perf_counter()
        order = order_rng.permutation(len(samples))
        losses = []
        for b in range(per_epoch):
            idx = order[b * settings.batch : (b + 1) * settings.batch]
            if idx.size < settings.batch:  # a full batch keeps one compiled shape
                idx = np.concatenate([idx, order[: settings.batch - idx.size]])
            images, classes, centres, distance = crop_batch(
                samples, idx, settings.seed, n, settings.scale, crop
            )
            if settings.stem:
                classes, centres, distance = _halved(classes, centres, distance)
            if focal:
                centres = sharpened(centres)
            params, state, loss = step(
                params, state, jnp.asarray(normalise(images)), jnp.asarray(classes),
                jnp.asarray(centres), jnp.asarray(distance),
            )  # fmt: skip
            losses.append(float(loss))
            n += 1
        mean = float(np.mean(losses))
        settings.losses.append(mean)
        on_epoch(epoch + 1, mean, time.perf_counter() - start)
    return params
