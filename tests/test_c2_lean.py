"""The C2 lean trace (softarm.experiments.c2_lean): a sphere's outline centre lies
outward of its centre's projection by the ellipse's half sum (checked against the
outline's extreme rays), and the summary's shares are signed towards the sun and
away from the principal point."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from softarm.experiments.c2_lean import outline_centre_offset, summary


def test_a_sphere_on_the_axis_has_its_outline_centred_on_it() -> None:
    assert outline_centre_offset(np.array([0.0, 0.0, 0.06]), 0.01) == pytest.approx([0.0, 0.0])


def test_an_off_axis_sphere_outline_centre_is_outward_by_the_extreme_rays_mean() -> None:
    p = np.array([0.02, 0.0, 0.06])  # in the x-z plane: the outline's extremes in x
    r = 0.011
    theta, alpha = np.arctan2(0.02, 0.06), np.arcsin(r / np.linalg.norm(p))
    expected = 0.5 * (np.tan(theta - alpha) + np.tan(theta + alpha))
    got = outline_centre_offset(p, r)
    assert got == pytest.approx([expected, 0.0])
    assert got[0] > 0.02 / 0.06  # outward of the centre's projection


def _row(centre: list[float], sun: list[float]) -> dict[str, Any]:
    return {
        "seed": 1, "berry": 0, "centre": centre, "perspective": [0.0, 0.0],
        "outline": [0.0, 0.0], "refined": centre, "sun": sun, "off_axis_px": [0.0, 5.0],
        "radius_px": 25.0,
    }  # fmt: skip


def test_summary_signs_the_shares() -> None:
    s = summary([_row([0.0, -0.3], [0.0, -1.0]), _row([0.0, -0.1], [0.0, -1.0])])
    assert s["fixes"] == 2 and s["berries"] == 1
    assert s["centre"]["along_sun_median_px"] == pytest.approx(0.2)  # towards the sun
    assert s["centre"]["outward_median_px"] == pytest.approx(-0.2)  # towards the axis
    assert summary([]) == {"fixes": 0, "berries": 0}
