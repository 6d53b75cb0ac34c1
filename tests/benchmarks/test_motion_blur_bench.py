"""What the motion blur adds to C2's camera model (issue 37 item 3): a 320 x 240 frame
(the harvest's half scale) through the row's C2 camera model without motion, and with
C2 turning and moving so that the scene smears 2, 6 and 16 px (a median, the 90th
percentile and the most seen in a row harvest), fingers kept sharp."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.sim.render.motion_blur import twist_flow
from softarm.sim.render.row_look import RowLook

SIZE = (320, 240)
FOCAL = 150.0


@pytest.mark.parametrize("smear_px", [0, 2, 6, 16])
def test_c2_camera_model_with_motion_blur(benchmark, smear_px: int) -> None:  # type: ignore[no-untyped-def]
    effects = RowLook.named("sun", 90104).c2
    image = np.random.default_rng(0).integers(0, 255, (SIZE[1], SIZE[0], 3)).astype(np.uint8)
    still = np.zeros(SIZE[::-1], bool)
    still[180:, 120:200] = True  # a finger at the rim
    # Half the smear from a pan, half from moving sideways 0.3 m from the scene.
    speed = smear_px / effects.exposure_s / FOCAL
    flow = twist_flow(
        np.array([0.15 * speed, 0.0, 0.0]), np.array([0.0, 0.5 * speed, 0.0]),
        FOCAL, ((SIZE[0] - 1) / 2, (SIZE[1] - 1) / 2), SIZE, 1 / 0.3,
    )  # fmt: skip
    rng = np.random.default_rng(1)
    out = benchmark(lambda: effects.apply(image, rng, flow_px_s=flow, still=still))
    assert out.shape == image.shape
