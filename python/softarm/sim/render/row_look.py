"""How the rendered row looks in daylight: named conditions (``sun``, ``overcast``,
``backlight``, ``dusk``; ``random`` draws one of them per seed), each a family of looks
whose parameters are drawn per seed from the ranges of :data:`LOOK_RANGES`, the one
table of them (docs/perception.md prints it with :func:`look_table`).

The row's content has two knobs of its own, held by name (``RowLook.named(...,
lookalikes=, fruit=)``) so that a sweep can vary them apart from the light:
``lookalikes`` (:data:`LOOKALIKES`: the share of the row's leaflets that are dead and
dark, and how many stones lie on the ground) and ``fruit`` (:data:`FRUIT_DENSITY`: how
many fruit the row hangs around the bush's). The row (:class:`~softarm.sim.render.row.Row`)
draws its counts from these ranges with its own seeded generator; ``normal`` is the
row every look drew before the knobs existed, draw for draw.

Angles are in degrees. The sun's azimuth is measured in the base frame's XY plane from
+X towards +Y: -90 is behind C1 (the row lit from the front), +90 behind the row (C1
looks into the light). ``warmth`` tints the sun from cool (-1) to orange (+1);
``overcast`` blends the sky from clear blue (0) to grey-white (1). The camera rows are
:class:`~softarm.sim.render.camera_effects.CameraEffects`'s parameters.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.checks import FloatArray
from softarm.errors import ParameterError
from softarm.sim.render.camera_effects import CameraEffects, StereoEffects
from softarm.sim.render.look import BushLook, _mix

__all__ = [
    "FAMILIES",
    "FRUIT_DENSITY",
    "LOOKALIKES",
    "LOOKS",
    "LOOK_RANGES",
    "RowLook",
    "look_table",
]

#: The named families, and what ``--look`` accepts.
FAMILIES = ("sun", "overcast", "backlight", "dusk")
LOOKS = (*FAMILIES, "random")

#: Look-alike levels: the share of the row's leaflets that are dead (dark, dry: they
#: pass for ripe fruit) and the range [lo, hi) of stones on the ground.
LOOKALIKES: dict[str, tuple[float, tuple[int, int]]] = {
    "few": (0.01, (2, 6)),
    "normal": (0.08, (15, 30)),
    "many": (0.25, (50, 80)),
}
#: Fruit density levels: the range [lo, hi) of fruit the row hangs around the bush's.
FRUIT_DENSITY: dict[str, tuple[int, int]] = {
    "sparse": (8, 20),
    "normal": (30, 70),
    "dense": (90, 130),
}

_COMMON: dict[str, tuple[float, float]] = {
    "sun_elevation": (35.0, 70.0),
    "sun_azimuth": (-150.0, -30.0),
    "sun_intensity": (0.9, 1.25),
    "ambient": (0.12, 0.28),
    "warmth": (-0.3, 0.3),
    "overcast": (0.0, 0.25),
    "fruit_specular": (0.6, 1.0),
    "fruit_shininess": (0.5, 1.0),
    "exposure_bias": (0.85, 1.2),
    "right_exposure": (0.95, 1.05),
    "rectification_px": (0.0, 0.3),
    "white_balance": (0.92, 1.08),
    "gain": (0.05, 0.3),
    "read_noise": (0.5, 2.5),
    "black_level": (0.0, 6.0),
    "vignetting": (0.1, 0.35),
    "blur_px_s": (0.0, 120.0),
    "jpeg_quality": (70.0, 95.0),
}

#: Every family's parameter ranges (lo, hi), drawn uniformly per seed.
LOOK_RANGES: dict[str, dict[str, tuple[float, float]]] = {
    "sun": dict(_COMMON),
    "overcast": {
        **_COMMON,
        "sun_elevation": (40.0, 85.0),
        "sun_azimuth": (-180.0, 180.0),
        "sun_intensity": (0.15, 0.35),
        "ambient": (0.45, 0.65),
        "overcast": (0.75, 1.0),
        "fruit_specular": (0.2, 0.5),
    },
    "backlight": {
        **_COMMON,
        "sun_elevation": (12.0, 40.0),
        "sun_azimuth": (40.0, 140.0),
        "ambient": (0.15, 0.3),
        "exposure_bias": (0.7, 1.1),
    },
    "dusk": {
        **_COMMON,
        "sun_elevation": (3.0, 12.0),
        "sun_azimuth": (-180.0, 180.0),
        "sun_intensity": (0.3, 0.6),
        "ambient": (0.06, 0.15),
        "warmth": (0.6, 1.0),
        "overcast": (0.1, 0.6),
        "gain": (0.3, 0.8),
        "read_noise": (2.0, 5.0),
        "blur_px_s": (60.0, 300.0),
        "exposure_bias": (0.35, 0.6),
    },
}


@dataclass(frozen=True)
class RowLook(BushLook):
    """A :class:`BushLook` with the row's daylight: the family ``name``, the sun's
    elevation and azimuth (deg), the sky's colours, the fruit's gloss, the ripe
    palette drawn from and the cameras (see the module docstring)."""

    name: str
    sun_elevation: float
    sun_azimuth: float
    sky_zenith: FloatArray
    sky_horizon: FloatArray
    fruit_specular: float
    fruit_shininess: float
    stereo: StereoEffects
    c2: CameraEffects
    blur_px_s: float
    lookalikes: str = "normal"
    fruit: str = "normal"

    @classmethod
    def named(
        cls, name: str, seed: int, lookalikes: str = "normal", fruit: str = "normal"
    ) -> RowLook:
        """A look of family ``name`` (one of :data:`LOOKS`) drawn from ``seed``, its row
        holding ``lookalikes`` (a key of :data:`LOOKALIKES`) and ``fruit`` (a key of
        :data:`FRUIT_DENSITY`).

        Raises:
            ParameterError: a name, level or density not among those.
        """
        if name not in LOOKS:
            raise ParameterError(f"look must be one of {', '.join(LOOKS)}, got {name!r}")
        if lookalikes not in LOOKALIKES:
            known = ", ".join(LOOKALIKES)
            raise ParameterError(f"lookalikes must be one of {known}, got {lookalikes!r}")
        if fruit not in FRUIT_DENSITY:
            known = ", ".join(FRUIT_DENSITY)
            raise ParameterError(f"fruit must be one of {known}, got {fruit!r}")
        rng = np.random.default_rng([seed, 0x50E])
        if name == "random":
            name = FAMILIES[int(rng.integers(len(FAMILIES)))]
        r = {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in LOOK_RANGES[name].items()}
        el, az = np.radians(r["sun_elevation"]), np.radians(r["sun_azimuth"])
        toward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        w = r["warmth"]
        sun = np.array([1.0 + 0.1 * w, 1.0 - 0.12 * max(w, 0.0), 1.0 - 0.45 * w])
        grey = r["overcast"]
        zenith = (1 - grey) * np.array([0.30, 0.50, 0.85]) + grey * np.array([0.72, 0.74, 0.76])
        horizon = (1 - grey) * np.array([0.70, 0.80, 0.92]) + grey * np.array([0.85, 0.85, 0.85])
        if name == "dusk":
            zenith, horizon = zenith * 0.45, np.array([0.95, 0.60, 0.35]) * 0.8
        base = BushLook.random(seed)
        return cls(
            light_direction=-toward,
            light_colour=sun / sun.max(),
            light_intensity=r["sun_intensity"],
            ambient=r["ambient"],
            ripe_colour=base.ripe_colour,
            cane_colour=base.cane_colour,
            leaf_colour=base.leaf_colour,
            background_colour=horizon,
            ground_colour=_mix(rng, [0.36, 0.28, 0.20], [0.22, 0.18, 0.14]),
            leaves_per_cane=base.leaves_per_cane,
            clutter=int(rng.integers(8, 20)),
            berry_scale=(0.8, 1.2),
            seed=seed,
            name=name,
            sun_elevation=r["sun_elevation"],
            sun_azimuth=r["sun_azimuth"],
            sky_zenith=zenith,
            sky_horizon=horizon,
            fruit_specular=r["fruit_specular"],
            fruit_shininess=r["fruit_shininess"],
            stereo=_stereo(r, rng),
            c2=_camera(r, rng),
            blur_px_s=r["blur_px_s"],
            lookalikes=lookalikes,
            fruit=fruit,
        )

    @property
    def dead_share(self) -> float:
        """The share of the row's leaflets that are dead (:data:`LOOKALIKES`)."""
        return LOOKALIKES[self.lookalikes][0]

    @property
    def stone_range(self) -> tuple[int, int]:
        """The range [lo, hi) of stones on the row's ground (:data:`LOOKALIKES`)."""
        return LOOKALIKES[self.lookalikes][1]

    @property
    def fruit_range(self) -> tuple[int, int]:
        """The range [lo, hi) of the row's own fruit (:data:`FRUIT_DENSITY`)."""
        return FRUIT_DENSITY[self.fruit]

    def ripe_shade(self, rng: np.random.Generator) -> FloatArray:
        """A ripe fruit's colour: blue-black (a glossy berry reflecting the sky),
        black-purple or red-purple, a little darker or lighter."""
        palette = (
            np.array([0.07, 0.06, 0.13]),  # blue-black
            np.array([0.10, 0.03, 0.11]),  # black-purple
            np.array([0.20, 0.04, 0.12]),  # red-purple
        )
        k = int(rng.choice(3, p=(0.3, 0.5, 0.2)))
        return palette[k] * rng.uniform(0.7, 1.3)


def _camera(r: dict[str, float], rng: np.random.Generator) -> CameraEffects:
    wb = rng.uniform(*LOOK_RANGES["sun"]["white_balance"], size=3)
    return CameraEffects(
        exposure=None,
        exposure_bias=r["exposure_bias"],
        white_balance=(float(wb[0]), 1.0, float(wb[2])),
        gain=r["gain"],
        read_noise=r["read_noise"],
        black_level=r["black_level"],
        vignetting=r["vignetting"],
        exposure_s=0.01,
        jpeg_quality=round(r["jpeg_quality"]),
    )


def _stereo(r: dict[str, float], rng: np.random.Generator) -> StereoEffects:
    angle = rng.uniform(0, 2 * np.pi)
    offset = (r["rectification_px"] * np.cos(angle), r["rectification_px"] * np.sin(angle))
    return StereoEffects(_camera(r, rng), r["right_exposure"], (float(offset[0]), float(offset[1])))


def look_table() -> str:
    """:data:`LOOK_RANGES` as a Markdown table (a row per parameter, a column per
    family)."""
    head = "| parameter | " + " | ".join(FAMILIES) + " |"
    rule = "| --- |" + " --- |" * len(FAMILIES)
    rows = [
        f"| {key} | "
        + " | ".join(f"{LOOK_RANGES[f][key][0]:g} to {LOOK_RANGES[f][key][1]:g}" for f in FAMILIES)
        + " |"
        for key in _COMMON
    ]
    return "\n".join([head, rule, *rows])
