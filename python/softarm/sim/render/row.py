"""The hedgerow around a :class:`~softarm.sim.bush.Bush` (``--world row``): the bush's
canes and berries stay where the generator put them (the arm reaches them as in the
rendered bush), and the row adds what a field has around them: canes arching across
the whole row, fruit hanging from them at every stage in touching clusters, a dense
wall of leaflets (some dead and dark), trellis posts and wires, the ground with its
mulch, stones and drip line, and the next row behind.

The row runs along the base frame's X axis, its centre plane at ``ROW_Y``; C1 looks at
it obliquely from in front (-Y). Everything is a function of the look's seed. The
row's own canes and fruit are kept out of the approach corridors of the bush's berries
(as the bush's canes are), so every berry the bush generator placed stays reachable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.checks import FloatArray
from softarm.geometry import APPROACH_CONE_DEG, cone_axes
from softarm.sim.bush import PLUS_Y, Branch, Bush
from softarm.sim.render.row_look import RowLook

__all__ = ["ROW_FRUIT_ID", "STAGES", "STAGE_RIPENESS", "Row", "RowFruit", "row_canes", "stage_of"]

#: Fruit stages, green to ripe (the fruit goes green -> red -> turning -> black).
STAGES = ("green", "red", "turning", "ripe")
#: Each stage's ripeness in [0, 1] (a bush berry keeps its own); under 0.5 is not ripe.
STAGE_RIPENESS = {"green": 0.0, "red": 0.25, "turning": 0.45, "ripe": 1.0}
#: The row's own fruit are numbered from here (the bush's keep their tag ids).
ROW_FRUIT_ID = 1000
#: The row's centre plane (y, m), its half-length along X (m), the ground's height.
ROW_Y = 0.62
ROW_HALF = 1.3
GROUND_Z = -0.45
#: Trellis wire heights (m) and post positions along the row (m).
WIRES_Z = (-0.05, 0.35, 0.75)
POSTS_X = (-1.1, 0.55)
#: The row's canes and leaflets (its fruit, dead leaflets and stones: the look's
#: ``fruit_range``, ``dead_share`` and ``stone_range``, softarm.sim.render.row_look).
ROW_CANES = (18, 28)
LEAFLETS = (380, 520)
#: Stage odds of the row's fruit (green, red, turning, ripe).
STAGE_ODDS = (0.22, 0.23, 0.15, 0.40)
#: Clear distance (m) of the row's canes and fruit from the bush's approach corridors.
CANE_CLEARANCE = 0.05
FRUIT_CLEARANCE = 0.04


@dataclass(frozen=True)
class RowFruit:
    """One fruit: its id (the bush berry's tag id, or from ROW_FRUIT_ID), centre (base
    frame, m), stage (one of :data:`STAGES`) and size factor."""

    fruit_id: int
    position: FloatArray
    stage: str
    scale: float


@dataclass(frozen=True)
class Leaflet:
    """A leaflet: centre, rotation (its x along the midrib, z its normal), length (m) and
    whether it is dead (dark, dry: a look-alike)."""

    centre: FloatArray
    rotation: FloatArray
    length: float
    dead: bool


@dataclass(frozen=True)
class Row:
    """The row's parts (see the module docstring); ``canes`` are the row's own, their
    ids following the bush's."""

    fruit: list[RowFruit]
    canes: list[Branch]
    leaflets: list[Leaflet]
    stones: FloatArray
    seed: int

    @classmethod
    def generate(cls, bush: Bush, look: RowLook) -> Row:
        """The row around ``bush`` drawn from ``look``'s seed."""
        rng, corridors, canes = _first_draws(bush, look)
        fruit = [
            RowFruit(b.tag_id, b.position, stage_of(b.ripeness, rng), float(rng.uniform(0.9, 1.1)))
            for b in bush.berries
        ]
        fruit += _row_fruit(rng, canes, corridors, [f.position for f in fruit], look.fruit_range)
        every = [*bush.branches, *canes]
        lines = [(b.position - 0.08 * PLUS_Y, b.position) for b in bush.berries]
        leaflets = _leaflets(rng, every, lines, look.dead_share)
        n_stones = int(rng.integers(*look.stone_range))
        stones = np.column_stack(
            [
                rng.uniform(-ROW_HALF, ROW_HALF, n_stones),
                rng.uniform(ROW_Y - 0.7, ROW_Y + 0.4, n_stones),
                rng.uniform(0.006, 0.03, n_stones),  # radius
            ]
        )
        return cls(fruit, canes, leaflets, stones, look.seed)

    def stage(self, fruit_id: int) -> str | None:
        """The stage of fruit ``fruit_id``, None if no such fruit."""
        fruit = self.find(fruit_id)
        return None if fruit is None else fruit.stage

    def find(self, fruit_id: int) -> RowFruit | None:
        """Fruit ``fruit_id``, None if no such fruit."""
        return next((f for f in self.fruit if f.fruit_id == fruit_id), None)


def row_canes(bush: Bush, look: RowLook) -> list[Branch]:
    """The canes :meth:`Row.generate` draws around ``bush`` for ``look``, without the rest
    of the row (its leaflets take seconds to draw): the truth the simulated harvest
    scores contacts and the cane map on."""
    return _first_draws(bush, look)[2]


def _first_draws(
    bush: Bush, look: RowLook
) -> tuple[np.random.Generator, list[tuple[FloatArray, FloatArray]], list[Branch]]:
    """The row's generator, the bush's approach corridors and the row's canes, the
    first thing drawn (so :func:`row_canes` draws the same canes as the whole row)."""
    rng = np.random.default_rng([look.seed, 0x20E])
    corridors = _corridors(bush)
    return rng, corridors, _row_canes(rng, corridors)


def stage_of(ripeness: float, rng: np.random.Generator) -> str:
    """A bush berry's stage: ripe at ripeness 0.5 or more, else green, red or turning
    (turning fruit is not ripe: part of it is still red)."""
    if ripeness >= 0.5:
        return "ripe"
    return str(rng.choice(STAGES[:3], p=(0.35, 0.4, 0.25)))


def _corridors(bush: Bush) -> list[tuple[FloatArray, FloatArray]]:
    """The bush's approach corridors (as :meth:`Bush.generate` keeps its canes out of)."""
    return [
        (b.position - 0.15 * a, b.position + 0.02 * a)
        for b in bush.berries
        for a in cone_axes(PLUS_Y, APPROACH_CONE_DEG)
    ]


def _clear(points: FloatArray, corridors: list[tuple[FloatArray, FloatArray]], gap: float) -> bool:
    for a, b in corridors:
        ab = b - a
        u = np.clip((points - a) @ ab / (ab @ ab), 0.0, 1.0)
        if np.min(np.linalg.norm(points - (a + u[:, None] * ab), axis=1)) < gap:
            return False
    return True


def _row_canes(
    rng: np.random.Generator, corridors: list[tuple[FloatArray, FloatArray]]
) -> list[Branch]:
    """Canes rising from the crown of the row (at the ground along its centre) and
    arching over to either side, crossing each other, clear of the corridors."""
    out: list[Branch] = []
    want = int(rng.integers(*ROW_CANES))
    for _ in range(want * 6):
        if len(out) == want:
            break
        base = np.array(
            [rng.uniform(-ROW_HALF, ROW_HALF), ROW_Y + rng.normal(0, 0.04), GROUND_Z + 0.1]
        )
        reach = rng.uniform(0.3, 0.9) * rng.choice([-1.0, 1.0])
        top = np.array([base[0] + reach, ROW_Y + rng.uniform(-0.28, 0.15), rng.uniform(0.25, 1.0)])
        mid = 0.5 * (base + top) + np.array(
            [0.0, rng.uniform(-0.12, 0.05), rng.uniform(0.15, 0.35)]
        )
        # The quadratic Bezier base-mid-top as a cubic in the power basis.
        c0, c1, c2 = base, 2 * (mid - base), base - 2 * mid + top
        branch = Branch(np.column_stack([c0, c1, c2, np.zeros(3)]))
        if _clear(branch.points(40), corridors, CANE_CLEARANCE):
            out.append(branch)
    return out


def _row_fruit(
    rng: np.random.Generator,
    canes: list[Branch],
    corridors: list[tuple[FloatArray, FloatArray]],
    taken: list[FloatArray],
    count: tuple[int, int],
) -> list[RowFruit]:
    """Clusters of 1-5 fruit that touch, hanging in front of the row's canes (their
    number drawn from ``count``, [lo, hi))."""
    out: list[RowFruit] = []
    want = int(rng.integers(*count))
    placed = list(taken)
    for _ in range(want * 10):
        if len(out) >= want or not canes:
            break
        cane = canes[int(rng.integers(len(canes)))]
        stem = cane.points(30)[int(rng.integers(10, 30))]
        size = int(rng.choice([1, 2, 3, 4, 5], p=(0.3, 0.25, 0.2, 0.15, 0.1)))
        centre = stem + np.array([0.0, -0.025, -0.03])
        for k in range(size):
            angle = rng.uniform(0, 2 * np.pi)
            pos = centre + (0.0 if k == 0 else 0.021) * np.array(
                [np.cos(angle), 0.3 * np.sin(angle), np.sin(angle)]
            )
            if any(np.linalg.norm(pos - p) < 0.019 for p in placed):
                continue  # would sink into another fruit: touching, not overlapping
            if not _clear(pos[None, :], corridors, FRUIT_CLEARANCE):
                continue
            stage = STAGES[int(rng.choice(4, p=STAGE_ODDS))]
            out.append(RowFruit(ROW_FRUIT_ID + len(out), pos, stage, float(rng.uniform(0.8, 1.15))))
            placed.append(pos)
            centre = pos
    return out


def _leaflets(
    rng: np.random.Generator,
    canes: list[Branch],
    lines: list[tuple[FloatArray, FloatArray]],
    dead_share: float,
) -> list[Leaflet]:
    """Leaflets along every cane and through the hedge's volume, facing mostly out of
    the row (±Y), kept out of the last 8 cm before each berry; ``dead_share`` of them
    dead."""
    out: list[Leaflet] = []
    want = int(rng.integers(*LEAFLETS))
    points = np.vstack([c.points(30) for c in canes])
    for _ in range(want * 3):
        if len(out) == want:
            break
        if rng.uniform() < 0.6:
            centre = points[int(rng.integers(len(points)))] + rng.normal(0.0, 0.05, 3)
        else:  # the hedge's body
            centre = np.array(
                [
                    rng.uniform(-ROW_HALF, ROW_HALF),
                    ROW_Y + rng.uniform(-0.12, 0.2),
                    rng.uniform(-0.35, 0.95),
                ]
            )
        length = float(rng.uniform(0.05, 0.09))
        if not _clear(centre[None, :], lines, length + 0.02):
            continue  # as the bush's own leaves (mjcf._leaves)
        out.append(Leaflet(centre, _leaf_rotation(rng), length, bool(rng.uniform() < dead_share)))
    return out


def _leaf_rotation(rng: np.random.Generator) -> FloatArray:
    """A leaflet's frame: its normal mostly along ±Y (out of the row), tilted up to 60
    deg, its midrib pointing anywhere in its plane but mostly down and out."""
    normal = np.array([rng.normal(0, 0.5), rng.choice([-1.0, 1.0]) * 1.0, rng.normal(0.2, 0.5)])
    normal /= np.linalg.norm(normal)
    along = np.cross(normal, [0.0, 0.0, 1.0])
    if np.linalg.norm(along) < 1e-6:
        along = np.array([1.0, 0.0, 0.0])
    along /= np.linalg.norm(along)
    turn = rng.uniform(-np.pi, np.pi)
    side = np.cross(normal, along)
    x = np.cos(turn) * along + np.sin(turn) * side
    return np.column_stack([x, np.cross(normal, x), normal])
