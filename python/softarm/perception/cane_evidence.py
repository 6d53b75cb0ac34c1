"""Whether a fitted curve is a cane by its evidence, not by its length alone.

With a larger point budget and a support counted in length
(:attr:`softarm.perception.cane_curves.CurveSearch.support_length`), the curve search
finds more of the row's canes, but also phantoms that cover as much length as a short
true cane: true canes placed at a wrong depth (a stereo match to the neighbouring
cane), leaf edges and speckled ground that passes the colour mask. What tells them
apart on the tuning renders (docs/perception.md, "Which cane pixels") is:

- the points per metre of the curve: a cane seen whole gives a run of cane pixels
  as wide as the cane all along it; a phantom is a thin or broken trail of matches;
- the radius its pixels give at their depth (the mask's width times depth over the
  focal length): a run 1–2 px wide, or a cane placed too near, is thinner than any
  cane (the rendered canes' radii are 2.5–4 mm, a blackberry cane's more);
- the count of points, as the count-based support has it.

The thresholds were tuned on seeds 311000–311008 (sun, overcast, dusk, bush) with
8,000 points and an 8 cm support; on fresh seeds 310160–310179 the overcast map's
precision after the self-filter fell 0.028 below today's default, so the check is an
option (``CaneSettings.evidence``), off by default. A true cane placed at a wrong depth
passes it: its run is as wide and as dense as a cane's (on the tuning renders, the
next row's canes aliased into the stereo's range: ``CaneSettings.match_far``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.checks import FloatArray, finite_real
from softarm.errors import ParameterError
from softarm.perception.cane_curves import curve_points

__all__ = ["CaneEvidence", "curve_length", "shows_a_cane"]


@dataclass(frozen=True)
class CaneEvidence:
    """What a fitted curve must show to be kept as a cane.

    min_points: fewest points fitted to it.
    min_density: fewest points per metre of the fitted curve (depends on the point
        budget, as ``min_points`` does: tuned for 8,000 points within the reach).
    min_radius: the smallest median radius (m) of its points.

    Raises:
        ParameterError: a field is not a finite number >= 0 (``min_points`` an int).
    """

    min_points: int = 70
    min_density: float = 350.0
    min_radius: float = 0.00175

    def __post_init__(self) -> None:
        if not isinstance(self.min_points, int) or isinstance(self.min_points, bool):
            raise ParameterError(f"evidence.min_points must be an int, got {self.min_points!r}")
        for name in ("min_points", "min_density", "min_radius"):
            value = getattr(self, name)
            if not finite_real(value) or value < 0:
                raise ParameterError(f"evidence.{name} must be a number >= 0, got {value!r}")


def curve_length(coeffs: FloatArray) -> float:
    """The length (m) of the curve ``coeffs`` (3, d+1) over u in [0, 1]."""
    dense = curve_points(np.asarray(coeffs, dtype=np.float64))
    return float(np.sum(np.linalg.norm(np.diff(dense, axis=0), axis=1)))


def shows_a_cane(n_points: int, coeffs: FloatArray, radius: float, evidence: CaneEvidence) -> bool:
    """Whether a curve ``coeffs`` fitted to ``n_points`` points of median ``radius``
    (m) has the ``evidence`` of a cane."""
    density = n_points / max(curve_length(coeffs), 1e-9)
    return (
        n_points >= evidence.min_points
        and density >= evidence.min_density
        and radius >= evidence.min_radius
    )
