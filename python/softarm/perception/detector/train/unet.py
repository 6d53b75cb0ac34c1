"""The detector's network in JAX: a small U-Net (three poolings, 8–32 channels) whose
layers are all ONNX operators OpenCV's DNN module runs (3×3 convolutions, ReLU, 2×2 max
pooling, nearest upsampling, concatenation); :mod:`.onnx_export` writes the same graph.

Parameters are a flat dict ``name -> (kernel (kh, kw, cin, cout), bias (cout,))`` of
:data:`LAYERS`, images NHWC."""

from __future__ import annotations

from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from softarm.perception.detector.network import N_OUTPUTS

__all__ = ["LAYERS", "WIDTHS", "apply", "init_params"]

#: Channels of the four levels (full, 1/2, 1/4, 1/8 resolution).
WIDTHS = (8, 16, 24, 32)
_C1, _C2, _C3, _C4 = WIDTHS
#: (name, kernel size, in channels, out channels), in the order the graph runs them.
LAYERS: tuple[tuple[str, int, int, int], ...] = (
    ("enc1", 3, 3, _C1),
    ("enc2a", 3, _C1, _C2),
    ("enc2b", 3, _C2, _C2),
    ("enc3a", 3, _C2, _C3),
    ("enc3b", 3, _C3, _C3),
    ("enc4a", 3, _C3, _C4),
    ("enc4b", 3, _C4, _C4),
    ("dec3", 3, _C4 + _C3, _C3),
    ("dec2", 3, _C3 + _C2, _C2),
    ("dec1", 3, _C2 + _C1, _C1),
    ("head", 1, _C1, N_OUTPUTS),
)

Params = dict[str, tuple[Any, Any]]


def init_params(seed: int) -> Params:
    """He-initialised parameters, deterministic in ``seed``."""
    rng = np.random.default_rng(seed)
    params: Params = {}
    for name, k, cin, cout in LAYERS:
        std = np.sqrt(2.0 / (k * k * cin))
        w = rng.normal(0.0, std, (k, k, cin, cout)).astype(np.float32)
        params[name] = (jnp.asarray(w), jnp.zeros((cout,), jnp.float32))
    return params


def _conv(params: Params, name: str, x: Any, relu: bool = True) -> Any:
    w, b = params[name]
    y = jax.lax.conv_general_dilated(
        x, w, (1, 1), "SAME", dimension_numbers=("NHWC", "HWIO", "NHWC")
    )
    y = y + b
    return jax.nn.relu(y) if relu else y


def _pool(x: Any) -> Any:
    return jax.lax.reduce_window(x, -jnp.inf, jax.lax.max, (1, 2, 2, 1), (1, 2, 2, 1), "VALID")


def _up(x: Any) -> Any:
    return jnp.repeat(jnp.repeat(x, 2, axis=1), 2, axis=2)


def apply(params: Params, x: Any) -> Any:
    """(N, H, W, N_OUTPUTS) logits of a normalised (N, H, W, 3) batch (H, W multiples of 8)."""
    s1 = _conv(params, "enc1", x)
    s2 = _conv(params, "enc2b", _conv(params, "enc2a", _pool(s1)))
    s3 = _conv(params, "enc3b", _conv(params, "enc3a", _pool(s2)))
    s4 = _conv(params, "enc4b", _conv(params, "enc4a", _pool(s3)))
    d3 = _conv(params, "dec3", jnp.concatenate([_up(s4), s3], axis=-1))
    d2 = _conv(params, "dec2", jnp.concatenate([_up(d3), s2], axis=-1))
    d1 = _conv(params, "dec1", jnp.concatenate([_up(d2), s1], axis=-1))
    return _conv(params, "head", d1, relu=False)
