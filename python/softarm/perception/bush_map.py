"""The bush map: the berries found so far, ripe ones to pick and unripe ones to leave,
each with its position in the base frame and how often it was seen, and the canes
fitted from C1. Built from C1 at IDLE and refreshed each time the arm is home, since the
arm and the fruit already picked hide parts of the bush. The ripe fruit C1 finds but
cannot place are kept as sight lines until C2 places them
(:mod:`softarm.perception.sight_lines`)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from softarm.checks import FloatArray, as_array
from softarm.errors import InputError
from softarm.perception.berries import BerryDetection, Ripeness, ripe_by_votes
from softarm.perception.sight_lines import Placing, SightLine, same_line

if TYPE_CHECKING:
    from softarm.perception.canes import CaneFit

__all__ = ["FRUIT_RADIUS", "BushMap", "MappedBerry"]

#: The nominal radius (m) of a fruit's outline: 1.5–2.5 cm across.
FRUIT_RADIUS = 0.01


@dataclass
class MappedBerry:
    """One berry of the map: its ``id`` (the map's own, not a tag), mean ``position``
    (base frame, m) and outline ``radius`` (m) over its ``sightings``, and the ripe
    share of those sightings."""

    id: int
    position: FloatArray
    radius: float
    ripe_votes: float
    sightings: int = 1

    @property
    def ripeness(self) -> Ripeness:
        """Ripe when most sightings said so (the NIR sensor decides at the grasp)."""
        return "ripe" if ripe_by_votes(self.ripe_votes, self.sightings) else "unripe"


@dataclass
class BushMap:
    """Berries merged across C1 views: a detection within ``merge_distance`` of a known
    berry is that berry seen again; a detection without a position is not mapped."""

    merge_distance: float = 0.02
    berries: list[MappedBerry] = field(default_factory=list)
    canes: list[CaneFit] = field(default_factory=list)
    #: C1's cane points (:func:`~softarm.perception.canes.cane_points`, (n, 4)) the
    #: canes were last fitted from, for a refit with other views' (None before).
    cane_points: FloatArray | None = None
    #: The ripe fruit C1 found without a position, each with C2's crossings so far.
    unplaced: list[Placing] = field(default_factory=list)
    #: Where C1's rays to the mapped berries start (base frame): the middle of its
    #: stereo baseline (:func:`~softarm.perception.two_eyes.ray_origin`); None before
    #: a stereo view, or for a map not built from one (C1's optical centre then).
    ray_origin: FloatArray | None = None

    def update(self, detections: Iterable[BerryDetection]) -> int:
        """Merge one view's detections (positions in the base frame, as
        :func:`~softarm.perception.stereo.locate_berries` gives them); the number of
        berries new to the map. The whole view is checked before any of it is merged.

        Raises:
            InputError: a detection placed in the camera frame (``frame`` "camera"),
                or a position that is not (3,) or not finite (ShapeError,
                NonFiniteError): a NaN would spread to every berry it merges with.
        """
        placed = [(d, _base_position(d, k)) for k, d in enumerate(detections)]
        new = 0
        for d, position in placed:
            if position is None:
                continue
            vote = d.ripe_vote
            known = self._near(position)
            if known is None:
                radius = d.radius_m or FRUIT_RADIUS
                self.berries.append(MappedBerry(len(self.berries), position, radius, vote))
                new += 1
            else:
                n = known.sightings
                known.position = (known.position * n + position) / (n + 1)
                known.radius = (known.radius * n + (d.radius_m or known.radius)) / (n + 1)
                known.ripe_votes += vote
                known.sightings = n + 1
        return new

    def note_unplaced(self, lines: Iterable[SightLine]) -> None:
        """Keep the ripe ones of one view's sight lines: a line that passes within
        ``merge_distance`` of a mapped berry is that berry; one near a kept line is it
        seen again."""
        for line in lines:
            if not line.ripe or self._on_line(line):
                continue
            known = next((p.line for p in self.unplaced if same_line(p.line, line)), None)
            if known is None:
                self.unplaced.append(Placing(line))
            else:
                known.ripe_votes += line.ripe_votes
                known.sightings += line.sightings

    def place(self, placing: Placing, position: FloatArray) -> MappedBerry:
        """Map the fruit of ``placing`` at ``position`` (C2 placed it); it leaves the
        unplaced ones.

        Raises:
            InputError: ``position`` is not a finite (3,) point.
        """
        position = as_array(position, (3,), "position")
        line = placing.line
        distance = float(np.linalg.norm(position - line.origin))
        berry = MappedBerry(
            len(self.berries), np.asarray(position, dtype=np.float64).copy(),
            distance * float(np.sin(line.half_angle)), line.ripe_votes, line.sightings,
        )  # fmt: skip
        self.berries.append(berry)
        self.unplaced.remove(placing)
        return berry

    def get(self, berry_id: int) -> MappedBerry | None:
        """The berry of ``berry_id``, or None."""
        return next((b for b in self.berries if b.id == berry_id), None)

    def ripe(self) -> list[MappedBerry]:
        """The berries to pick."""
        return [b for b in self.berries if b.ripeness == "ripe"]

    def _on_line(self, line: SightLine) -> bool:
        """Whether a mapped berry lies within ``merge_distance`` of ``line``."""
        for b in self.berries:
            along = b.position - line.origin
            off = along - (along @ line.direction) * line.direction
            if float(np.linalg.norm(off)) <= self.merge_distance:
                return True
        return False

    def _near(self, position: FloatArray) -> MappedBerry | None:
        if not self.berries:
            return None
        gaps = [float(np.linalg.norm(b.position - position)) for b in self.berries]
        k = int(np.argmin(gaps))
        return self.berries[k] if gaps[k] <= self.merge_distance else None


def _base_position(d: BerryDetection, k: int) -> FloatArray | None:
    """A copy of detection ``k``'s position, checked: in the base frame, (3,), finite."""
    if d.position is None:
        return None
    if d.frame != "base":
        raise InputError(
            f"detections[{k}] is placed in the {d.frame} frame: the map holds base-frame "
            "positions (locate_berries gives them)"
        )
    return as_array(d.position, (3,), f"detections[{k}].position")
