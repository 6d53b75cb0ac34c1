"""The outline's match of a berry against the shading's veto
(``softarm.perception.stereo``): where the fruit's outline is alone against the
background, a shading cue that a pale background beside the fruit in one eye pulls away
does not veto it; where another fruit lies beside it on its rows, or a leaf hides it
differently in the two eyes, the veto stands."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.perception.berries import BerryDetection
from softarm.perception.stereo import OUTLINE_OVERLAP, _Cues, locate_berries
from softarm.vision.stereo_camera import StereoCamera

FRUIT = (40, 8, 25)  # BGR: black-purple
GROUND = (22, 30, 26)  # BGR: shaded ground, as dark as the fruit in grey
SKY = (200, 200, 200)  # BGR: pale and grey, no fruit colour
CENTRE = (330, 240)  # the berry in the left image (px)
RADIUS = 9
DISPARITY = 108  # f B / z at 1 m: 900 px x 0.12 m


def _disc(image: np.ndarray, centre: tuple[int, int], radius: int) -> None:
    yy, xx = np.mgrid[: image.shape[0], : image.shape[1]]
    image[(xx - centre[0]) ** 2 + (yy - centre[1]) ** 2 <= radius**2] = FRUIT


def _pair(neighbour: bool) -> tuple[np.ndarray, np.ndarray]:
    """A berry 1 m away on dark ground; in the right eye a pale strip of background lies
    behind its left edge (far behind it: in the left eye the strip lies 60 px to the
    left), which pulls the shading's match 5 px off. With ``neighbour`` a smaller berry
    lies 6 px to its right, as far away (of another size, so that the outline's match
    stays unique)."""
    left = np.full((480, 640, 3), GROUND, np.uint8)
    right = left.copy()
    x, y = CENTRE
    strip = slice(y - 20, y + 20)
    right[strip, x - DISPARITY - RADIUS - 3 : x - DISPARITY - RADIUS + 9] = SKY
    left[strip, x - 60 - RADIUS - 3 : x - 60 - RADIUS + 9] = SKY
    for cx, radius in ((x, RADIUS), (x + RADIUS + 12, 6))[: 1 + neighbour]:
        _disc(left, (cx, y), radius)
        _disc(right, (cx - DISPARITY, y), radius)
    return left, right


def _the_berry(found: list[BerryDetection]) -> BerryDetection:
    return min(found, key=lambda d: abs(d.center[0] - CENTRE[0]) + abs(d.center[1] - CENTRE[1]))


def test_a_lone_berry_stands_on_its_outline_where_the_shading_disagrees(
    stereo: StereoCamera,
) -> None:
    berry = _the_berry(locate_berries(*_pair(neighbour=False), stereo))
    assert berry.position is not None
    assert berry.position[2] == pytest.approx(1.0, abs=0.01)


def test_a_berry_beside_another_keeps_the_shadings_veto(stereo: StereoCamera) -> None:
    found = locate_berries(*_pair(neighbour=True), stereo)
    assert len(found) == 2
    assert _the_berry(found).position is None


def _silhouettes(hidden: bool) -> tuple[np.ndarray, np.ndarray, BerryDetection]:
    """The blurred-free silhouettes of a disc in both eyes 31 px apart, its right half
    behind a leaf in the right eye when ``hidden``; and its detection in the left."""
    yy, xx = np.mgrid[:100, :240]
    disc = (xx - 127) ** 2 + (yy - 47) ** 2 <= 7**2
    left = disc.astype(np.float32)
    right = np.zeros_like(left)
    right[:, :-31] = left[:, 31:]
    if hidden:
        right[:, 96:] = 0.0
    ys, xs = np.nonzero(disc)
    box = (int(xs.min()), int(ys.min()), int(np.ptp(xs)) + 1, int(np.ptp(ys)) + 1)
    det = BerryDetection((127.0, 47.0), 7.0, box, disc, 1.0, "ripe", 1.0)
    return left, right, det


@pytest.mark.parametrize("hidden", [False, True], ids=["seen whole", "half hidden"])
def test_an_outline_hidden_differently_in_the_two_eyes_is_not_alone(hidden: bool) -> None:
    left, right, det = _silhouettes(hidden)
    flat = np.full_like(left, 20.0)
    cues = _Cues((left, right), (flat, flat), det, (5.0, 80.0))
    # The shading has no unique match (flat) and the outline's is the only word.
    assert cues.by_shading is None
    assert cues._outline_alone(31.0) is not hidden
    assert 0.5 <= OUTLINE_OVERLAP < 1.0
