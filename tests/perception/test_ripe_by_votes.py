"""How a fruit seen several times is called ripe or unripe (:func:`ripe_by_votes`): by
the sum of its sightings' ripe votes against half the sightings, a tie counting as ripe
(the NIR sensor decides at the grasp)."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.perception.berries import BerryDetection, ripe_by_votes
from softarm.perception.bush_map import MappedBerry


@pytest.mark.parametrize(
    ("votes", "sightings", "ripe"),
    [
        (1.0, 1, True),
        (0.0, 1, False),
        (2.0, 3, True),  # most said ripe
        (1.0, 3, False),  # most said unripe
        (1.0, 2, True),  # a tie is ripe
        (1.5, 3, True),  # a tie is ripe
        (0.5, 1, True),  # a tie is ripe
        (0.999, 2, False),  # just short of half
        (1.001, 2, True),
    ],
)
def test_half_the_sightings_or_more_is_ripe(votes: float, sightings: int, ripe: bool) -> None:
    assert ripe_by_votes(votes, sightings) is ripe


def _detection(ripeness: str, probability: float) -> BerryDetection:
    mask = np.zeros((4, 4), bool)
    return BerryDetection((1.0, 1.0), 1.0, (0, 0, 2, 2), mask, 1.0, ripeness, probability)  # type: ignore[arg-type]


def test_a_ripe_and_an_unripe_sighting_as_sure_tie_and_the_map_calls_it_ripe() -> None:
    # Seen twice: once ripe at 0.9, once unripe at 0.9 (a ripe vote of 0.1): 1.0 of 2.
    votes = _detection("ripe", 0.9).ripe_vote + _detection("unripe", 0.9).ripe_vote
    berry = MappedBerry(0, np.zeros(3), 0.01, votes, sightings=2)
    assert berry.ripeness == "ripe"
    # The surer sighting decides when they are not as sure.
    votes = _detection("ripe", 0.6).ripe_vote + _detection("unripe", 0.9).ripe_vote
    assert MappedBerry(1, np.zeros(3), 0.01, votes, sightings=2).ripeness == "unripe"
