"""Estimates too uncertain to use (issue 26, item 14): with a tracker ten times noisier
than the rig's, ``softarm identify`` exited 0 with metres per psi several % off, and only
the metadata's standard deviations showed it. Each estimate with a standard deviation
above its tolerance is named here; ``identify`` warns, marks ``id.json``
(``metadata["poor_estimates"]``) and exits 1.

The tolerances: the default simulated rig identifies metres per psi to 0.08 % (one
standard deviation) and hysteresis to 0.002 psi; the fit's standard deviations are
about half the real errors (the tracker's filter and the play bias the estimate). A
1 % error in metres per psi is 1 % of every commanded elongation, a few mm at the end
effector; 0.2 psi is a seventh of the 1.5 psi of play the simulated regulators have.
"""

from __future__ import annotations

import numpy as np

from softarm.checks import FloatArray as F64

__all__ = ["HYSTERESIS_STD_PSI", "METRES_PER_PSI_REL_STD", "poor_estimates"]


#: The largest relative standard deviation of an elongation per psi.
METRES_PER_PSI_REL_STD = 0.01
#: The largest standard deviation (psi) of a hysteresis.
HYSTERESIS_STD_PSI = 0.2


def poor_estimates(metres_per_psi: F64, metres_per_psi_std: F64, hysteresis_std: F64) -> list[str]:
    """One line per estimate whose standard deviation exceeds its tolerance (a NaN
    standard deviation, an undetermined estimate, counts as exceeding)."""
    out = []
    rel = np.asarray(metres_per_psi_std) / np.abs(np.asarray(metres_per_psi))
    for i, r in enumerate(rel):
        if not r <= METRES_PER_PSI_REL_STD:
            out.append(
                f"metres_per_psi[{i}] +-{100 * r:.2g} % (tolerance "
                f"{100 * METRES_PER_PSI_REL_STD:g} %)"
            )
    for i, s in enumerate(np.asarray(hysteresis_std)):
        if not s <= HYSTERESIS_STD_PSI:
            out.append(f"hysteresis_psi[{i}] +-{s:.2g} psi (tolerance {HYSTERESIS_STD_PSI:g} psi)")
    return out
