"""The detector's network in JAX: a small U-Net (three poolings, 8–32 channels by
default, any four widths by :func:`layers`) whose layers are all ONNX operators
OpenCV's DNN module runs (3×3 convolutions, ReLU, 2×2 max pooling, nearest upsampling,
concatenation); :mod:`.onnx_export` writes the same graph.

With ``stem=True`` the first layer is a 6×6 convolution of stride 2 (:data:`STEM_KERNEL`):
the same as a space-to-depth of the image (each 2×2 block of pixels as 12 channels)
followed by a 3×3 convolution, so that the rest of the network runs at half the image's
resolution (today's cost) while its first layer sees every pixel of the full image
(fruit of a few pixels keep their detail). Its outputs are at half the input's size.

With ``boundary=True`` the head has one more output, after the heatmap: the boundary
class's logit (:mod:`..boundary`); with ``distance=True`` one more, last: the logit of
the normalised distance to the fruit's edge (:mod:`..distance`), which
:func:`with_distance` adds to a trained network (a fresh column of the head).

Parameters are a flat dict ``name -> (kernel (kh, kw, cin, cout), bias (cout,))`` of
:data:`LAYERS`, images NHWC."""

from __future__ import annotations

from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from softarm.errors import InputError
from softarm.perception.detector.network import N_OUTPUTS

__all__ = [
    "LAYERS",
    "STEM_KERNEL",
    "WIDTHS",
    "apply",
    "has_boundary",
    "init_params",
    "layers",
    "stem_of",
    "widths_of",
    "with_distance",
]

#: Channels of the four levels (full, 1/2, 1/4, 1/8 resolution) by default.
WIDTHS = (8, 16, 24, 32)
#: The stem's kernel (stride 2, padding 2): a 3×3 convolution over 2×2 pixel blocks.
STEM_KERNEL = 6


def layers(
    widths: tuple[int, ...] = WIDTHS,
    stem: bool = False,
    boundary: bool = False,
    distance: bool = False,
) -> tuple[tuple[str, int, int, int], ...]:
    """(name, kernel size, in channels, out channels) of a network of ``widths`` (four
    positive channel counts), in the order the graph runs them; with ``stem`` the first
    layer is the stride-2 stem, with ``boundary`` the head gives the boundary class too,
    with ``distance`` the normalised distance too.

    Raises:
        InputError: ``widths`` is not four positive integers.
    """
    if len(widths) != 4 or any(not isinstance(c, int) or c < 1 for c in widths):
        raise InputError(f"widths {widths!r}: four positive channel counts expected")
    c1, c2, c3, c4 = widths
    return (
        ("enc1", STEM_KERNEL if stem else 3, 3, c1),
        ("enc2a", 3, c1, c2),
        ("enc2b", 3, c2, c2),
        ("enc3a", 3, c2, c3),
        ("enc3b", 3, c3, c3),
        ("enc4a", 3, c3, c4),
        ("enc4b", 3, c4, c4),
        ("dec3", 3, c4 + c3, c3),
        ("dec2", 3, c3 + c2, c2),
        ("dec1", 3, c2 + c1, c1),
        ("head", 1, c1, N_OUTPUTS + int(boundary) + int(distance)),
    )


#: The layers of the default widths.
LAYERS = layers()

Params = dict[str, tuple[Any, Any]]


def init_params(
    seed: int,
    widths: tuple[int, ...] = WIDTHS,
    stem: bool = False,
    boundary: bool = False,
    distance: bool = False,
) -> Params:
    """He-initialised parameters of a network of ``widths`` (with the stride-2 stem when
    ``stem``, the boundary class when ``boundary``, the distance when ``distance``),
    deterministic in ``seed``."""
    rng = np.random.default_rng(seed)
    params: Params = {}
    for name, k, cin, cout in layers(widths, stem, boundary, distance):
        std = np.sqrt(2.0 / (k * k * cin))
        w = rng.normal(0.0, std, (k, k, cin, cout)).astype(np.float32)
        params[name] = (jnp.asarray(w), jnp.zeros((cout,), jnp.float32))
    return params


def with_distance(params: Params, seed: int) -> Params:
    """``params`` with one more output of the head, last: the distance's, He-initialised
    from ``seed`` as a fresh head's column is (the rest of the network as trained)."""
    w, b = params["head"]
    cin = int(w.shape[2])
    column = np.random.default_rng([seed, 2]).normal(0.0, np.sqrt(2.0 / cin), (1, 1, cin, 1))
    head = (
        jnp.concatenate([w, jnp.asarray(column.astype(np.float32))], axis=-1),
        jnp.concatenate([b, jnp.zeros((1,), jnp.float32)]),
    )
    return {**params, "head": head}


def widths_of(params: Params) -> tuple[int, int, int, int]:
    """The four channel counts of ``params`` (their first layer of each level)."""
    c1, c2, c3, c4 = (int(params[n][0].shape[-1]) for n in ("enc1", "enc2a", "enc3a", "enc4a"))
    return c1, c2, c3, c4


def has_boundary(params: Params, distance: bool = False) -> bool:
    """Whether ``params`` give the boundary class (their head's output count says, less
    the distance's output where they have it: ``distance``, which their record says)."""
    return int(params["head"][0].shape[-1]) - int(distance) == N_OUTPUTS + 1


def stem_of(params: Params) -> bool:
    """Whether ``params`` begin with the stride-2 stem (their first kernel's size says)."""
    return int(params["enc1"][0].shape[0]) == STEM_KERNEL


def _conv(params: Params, name: str, x: Any, relu: bool = True) -> Any:
    w, b = params[name]
    if int(w.shape[0]) == STEM_KERNEL:  # the stem: stride 2, padding 2 (ONNX's pads)
        pad = STEM_KERNEL // 2 - 1
        strides: tuple[int, int] = (2, 2)
        padding: str | tuple[tuple[int, int], tuple[int, int]] = ((pad, pad), (pad, pad))
    else:
        strides, padding = (1, 1), "SAME"
    y = jax.lax.conv_general_dilated(
        x, w, strides, padding, dimension_numbers=("NHWC", "HWIO", "NHWC")
    )
    y = y + b
    return jax.nn.relu(y) if relu else y


def _pool(x: Any) -> Any:
    return jax.lax.reduce_window(x, -jnp.inf, jax.lax.max, (1, 2, 2, 1), (1, 2, 2, 1), "VALID")


def _up(x: Any) -> Any:
    return jnp.repeat(jnp.repeat(x, 2, axis=1), 2, axis=2)


def apply(params: Params, x: Any) -> Any:
    """(N, H, W, N_OUTPUTS) logits of a normalised (N, H, W, 3) batch (H, W multiples of
    8), or (N, H/2, W/2, N_OUTPUTS) of a network with the stem (H, W multiples of 16)."""
    s1 = _conv(params, "enc1", x)
    s2 = _conv(params, "enc2b", _conv(params, "enc2a", _pool(s1)))
    s3 = _conv(params, "enc3b", _conv(params, "enc3a", _pool(s2)))
    s4 = _conv(params, "enc4b", _conv(params, "enc4a", _pool(s3)))
    d3 = _conv(params, "dec3", jnp.concatenate([_up(s4), s3], axis=-1))
    d2 = _conv(params, "dec2", jnp.concatenate([_up(d3), s2], axis=-1))
    d1 = _conv(params, "dec1", jnp.concatenate([_up(d2), s1], axis=-1))
    return _conv(params, "head", d1, relu=False)
