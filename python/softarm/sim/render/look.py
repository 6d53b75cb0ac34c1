"""How a rendered bush looks, drawn at random per seed: lighting (direction, intensity,
colour), leaf density, berry colours and sizes, clutter and the background.

Ripe fruit is black to black-purple and glossy; unripe fruit is red or green (the
fruit goes green → red → black). The dark look-alikes of a real row (shadowed leaves,
dead leaves, black mulch, irrigation line) are the clutter: a detector that keys on
"dark blob" alone fires on them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.checks import FloatArray

__all__ = ["BushLook"]


@dataclass(frozen=True)
class BushLook:
    """The appearance of one rendered bush (every colour RGB in [0, 1]).

    ``leaves_per_cane`` sets the leaf density; ``clutter`` is how many dark look-alikes
    lie about the scene; ``berry_scale`` multiplies the nominal fruit size (2.4 cm long,
    1.9 cm across) per berry.
    """

    light_direction: FloatArray
    light_colour: FloatArray
    light_intensity: float
    ambient: float
    ripe_colour: FloatArray
    cane_colour: FloatArray
    leaf_colour: FloatArray
    background_colour: FloatArray
    ground_colour: FloatArray
    leaves_per_cane: int
    clutter: int
    berry_scale: tuple[float, float]
    seed: int

    @classmethod
    def random(cls, seed: int) -> BushLook:
        """A look drawn from ``seed``: sun from above and in front of the bush, warm to
        cool white light at 0.6–1.0 intensity, 6–16 leaves a cane, 4–10 clutter items."""
        rng = np.random.default_rng([seed, 0x5EE])
        azimuth = rng.uniform(-np.pi, 0.0)  # from the camera's side of the bush (-Y)
        elevation = rng.uniform(np.radians(25), np.radians(75))
        toward = np.array(
            [np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth),
             np.sin(elevation)]
        )  # fmt: skip
        warmth = rng.uniform(-1.0, 1.0)
        light = np.array([1.0 + 0.08 * warmth, 1.0, 1.0 - 0.12 * warmth])
        return cls(
            light_direction=-toward,  # the direction the light travels
            light_colour=light / light.max(),
            light_intensity=float(rng.uniform(0.6, 1.0)),
            ambient=float(rng.uniform(0.25, 0.45)),
            ripe_colour=np.array([0.10, 0.03, 0.12]) * rng.uniform(0.6, 1.2),
            cane_colour=_mix(rng, [0.35, 0.45, 0.18], [0.42, 0.28, 0.16]),
            leaf_colour=_mix(rng, [0.18, 0.42, 0.12], [0.30, 0.52, 0.16]),
            background_colour=_mix(rng, [0.55, 0.60, 0.50], [0.35, 0.30, 0.22]),
            ground_colour=_mix(rng, [0.30, 0.24, 0.17], [0.08, 0.08, 0.08]),
            leaves_per_cane=int(rng.integers(6, 17)),
            clutter=int(rng.integers(4, 11)),
            berry_scale=(0.85, 1.15),
            seed=seed,
        )

    def unripe_colour(self, rng: np.random.Generator) -> FloatArray:
        """Red or green fruit, half and half, with some spread."""
        if rng.uniform() < 0.5:
            return _mix(rng, [0.65, 0.08, 0.08], [0.45, 0.05, 0.10])
        return _mix(rng, [0.45, 0.65, 0.20], [0.60, 0.70, 0.30])


def _mix(rng: np.random.Generator, a: list[float], b: list[float]) -> FloatArray:
    """A colour on the segment between ``a`` and ``b``."""
    t = rng.uniform()
    return (1 - t) * np.asarray(a) + t * np.asarray(b)
