"""The simulated bush in a rerun recording: the canes (sampled cubic curves) and the
berries as points labelled by tag, shared by the live view and the replay."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["RIPE", "SELECTED", "UNRIPE", "log_berries", "log_canes"]

#: Berry colours (RGB): ripe, unripe, the one being harvested.
RIPE, UNRIPE, SELECTED = (200, 30, 60), (90, 170, 60), (255, 0, 255)
CANE = (139, 69, 19)


def log_canes(stream: Any, rr: Any, branches: Sequence[Any], samples: int = 60) -> None:
    """The canes at ``world/canes``, static (they do not move in the simulation)."""
    strips = [b.points(samples) for b in branches]
    stream.log("world/canes", rr.LineStrips3D(strips, colors=[CANE], radii=0.004), static=True)


def log_berries(
    stream: Any,
    rr: Any,
    path: str,
    berries: Sequence[Any],
    selected: int | None = None,
    static: bool = False,
) -> None:
    """``berries`` (with ``tag_id``, ``position``, ``ripeness``) at ``path``: ripe red,
    unripe green, the ``selected`` tag magenta, each labelled ``tag N``."""
    colours = [
        SELECTED if b.tag_id == selected else RIPE if b.ripeness >= 0.5 else UNRIPE for b in berries
    ]
    points = rr.Points3D(
        np.array([b.position for b in berries], dtype=np.float64).reshape(-1, 3),
        labels=[f"tag {b.tag_id}" for b in berries],
        colors=colours,
        radii=0.01,
        show_labels=True,
    )
    stream.log(path, points, static=static)
