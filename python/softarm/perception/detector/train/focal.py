"""CenterNet's penalty-reduced focal loss on the centre heatmap (Zhou et al., "Objects as
Points", 2019), an option of ``softarm detector train --heatmap focal``.

The logistic loss of the default recipe fits the whole Gaussian around each centre, so
the network's heatmap is as broad as the target and two touching fruit give one hump
(their peaks merge). The focal loss counts only each centre's own pixel as positive and
every other pixel as negative, down-weighted by (1 − target)^BETA near a centre and by
p^ALPHA where the network is already sure: the network learns one sharp peak per fruit,
so the peaks of touching fruit stay apart. A centre's pixel is the target's local
maximum (the Gaussian of :mod:`.samples`, resized and cropped by the augmentation, no
longer peaks at exactly 1 there): :func:`sharpened` sets those pixels to 1.
"""

from __future__ import annotations

from typing import Any, cast

import cv2
import jax
import jax.numpy as jnp
import numpy as np
import numpy.typing as npt

__all__ = ["ALPHA", "BETA", "PEAK_MIN", "PRIOR", "focal_loss", "prior_bias", "sharpened"]

#: Focal exponents of CenterNet (the paper's alpha 2 and beta 4).
ALPHA = 2.0
BETA = 4.0
#: A local maximum of the target at least this high is a fruit's centre: a fruit's own
#: Gaussian peaks at 1 and keeps at least exp(-1/4) ≈ 0.78 when the augmentation resizes
#: it (sigma >= 1 px, sampled within half a pixel of its top); lower maxima are the
#: tails of a fruit whose centre a crop or a cut-out cut off.
PEAK_MIN = 0.7
#: The heatmap's initial probability everywhere (CenterNet's 0.1): with 0.5 the negatives'
#: loss, summed over every pixel, swamps the class loss in the first steps.
PRIOR = 0.1
_F32 = npt.NDArray[np.float32]


def sharpened(centres: _F32) -> _F32:
    """``centres`` ((N, H, W) or (H, W) target heatmaps) with each local maximum (3 × 3)
    of at least PEAK_MIN set to exactly 1: the focal loss's positives."""
    out = np.array(centres, np.float32, copy=True)
    maps = out.reshape((-1, *out.shape[-2:]))
    kernel = np.ones((3, 3), np.uint8)
    for m in maps:
        grown = cv2.dilate(m, kernel)
        m[(m >= grown) & (m >= PEAK_MIN)] = 1.0
    return out


def focal_loss(logits: Any, target: Any) -> Any:
    """The penalty-reduced focal loss of heatmap ``logits`` against ``target`` (any equal
    shapes; pixels at exactly 1 are centres), summed and divided by the number of centres
    (at least 1)."""
    log_p = jax.nn.log_sigmoid(logits)
    log_q = jax.nn.log_sigmoid(-logits)  # log(1 - p), stable for large logits
    p = jnp.exp(log_p)
    positive = target >= 1.0
    pos = jnp.where(positive, (1.0 - p) ** ALPHA * log_p, 0.0)
    neg = jnp.where(positive, 0.0, (1.0 - target) ** BETA * p**ALPHA * log_q)
    count = jnp.maximum(jnp.sum(positive), 1)
    return -(jnp.sum(pos) + jnp.sum(neg)) / count


def prior_bias() -> float:
    """The heatmap logit's initial bias: sigmoid(bias) = PRIOR."""
    return cast(float, np.log(PRIOR / (1.0 - PRIOR)))
