"""The cube tracking experiment's ``--without``: the row look with parts of C1's camera
model off, and nothing else changed."""

from __future__ import annotations

import pytest

from softarm.errors import ParameterError
from softarm.experiments.cube_tracking import without_parts
from softarm.sim.render.row_look import RowLook


def test_each_part_is_turned_off_and_the_rest_kept() -> None:
    look = RowLook.named("sun", 90011)
    off = without_parts(look, ("noise", "jpeg"))
    left, before = off.stereo.left, look.stereo.left
    assert (left.gain, left.read_noise, left.jpeg_quality) == (0.0, 0.0, None)
    assert left.exposure_s == before.exposure_s and off.blur_px_s == look.blur_px_s
    assert left.white_balance == before.white_balance and off.c2 == look.c2
    blurless = without_parts(look, ("blur",))
    assert blurless.stereo.left.exposure_s == 0.0 and blurless.blur_px_s == 0.0
    assert blurless.stereo.left.gain == before.gain


def test_no_part_is_the_same_look() -> None:
    look = RowLook.named("overcast", 90012)
    assert without_parts(look, ()) is look


def test_an_unknown_part_is_named() -> None:
    with pytest.raises(ParameterError, match="'glare'"):
        without_parts(RowLook.named("sun", 90013), ("glare",))
