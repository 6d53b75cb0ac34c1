"""Body geometry shared by the simulation and the harvest layer: the radii of the arm's
surfaces and the cane, and the fan of approach axes around a direction and how wide it
opens by default.

The radii are declared once, in the Rust core (``crates/softarm-core/src/body.rs``, with
the arm's whole :class:`softarm._core.Body`), and re-exported here. This module imports
only numpy and ``softarm._core``, so :mod:`softarm.sim` (the bush generator, the Cosserat
clearance) and :mod:`softarm.harvest` (clearance, placement) both take these from below
(see ``docs/architecture.md``, "Layers").
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

# Radius (m) of one pneumatic artificial muscle (5/8" braided sleeve, section II-A), of
# the gripper with its fingers around its axis, and of a blackberry cane.
from softarm._core import ACTUATOR_RADIUS, CANE_RADIUS, GRIPPER_RADIUS

__all__ = ["ACTUATOR_RADIUS", "APPROACH_CONE_DEG", "CANE_RADIUS", "GRIPPER_RADIUS", "cone_axes"]

FloatArray = npt.NDArray[np.float64]

#: How far (deg) a placement plan may tilt the approach from its axis: the default of
#: ``HarvestConfig.approach_cone_deg``, and the cone the simulated bush keeps its canes
#: out of (``softarm.sim.bush.Bush.generate``), so that every axis the planner may choose
#: is clear of the canes.
APPROACH_CONE_DEG = 20.0


def cone_axes(axis: FloatArray, cone_deg: float, rings: int = 2, per_ring: int = 8) -> FloatArray:
    """(1 + rings * per_ring, 3) unit axes: ``axis``, then rings at growing angles up to
    ``cone_deg`` around it."""
    a = axis / np.linalg.norm(axis)
    u = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    out = [a]
    for k in range(1, rings + 1):
        t = np.radians(cone_deg) * k / rings
        for phi in np.linspace(0, 2 * np.pi, per_ring, endpoint=False):
            out.append(np.cos(t) * a + np.sin(t) * (np.cos(phi) * u + np.sin(phi) * v))
    return np.array(out)
