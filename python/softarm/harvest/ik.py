"""Placement planning on the controller's model, before the loop closes on the cameras.

The resolver is a local method: from the straight ready pose, a target 90° away (the
gripper turns from +Z to face the bush along +Y) can leave it stuck on the joint limits,
and not every berry can be faced exactly along +Y. So placement first solves on the model:
for approach axes in a cone around +Y (squarest first), from several starts (the current
command and the best of a seeded batch of random configurations, scored by forward
kinematics), it looks for elongations reaching the pre-grasp pose AND the grasp pose.
The machine ramps the actuators to that solution, then servos on the cameras (eq. 22).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.harvest.config import HarvestConfig
from softarm.harvest.targets import approach_pose

__all__ = ["ModelIK", "cone_axes"]

FloatArray = npt.NDArray[np.float64]


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


class ModelIK:
    """Implements :class:`~softarm.harvest.interfaces.PlacementPlanner`.

    Args:
        resolver: a ``softarm.Resolver`` on the model (its ``solve`` refines each start).
        config: the machine's configuration (approach axis and cone, offsets).
        samples: random configurations scored per axis.
        starts: how many of the best-scored ones are refined (plus the current command).
        seed: seed of the random configurations.
    """

    def __init__(
        self,
        resolver: object,
        config: HarvestConfig,
        samples: int = 3000,
        starts: int = 4,
        seed: int = 0,
    ) -> None:
        self.resolver = resolver
        self.arm = resolver.arm  # type: ignore[attr-defined]
        self.cfg = config
        self.samples, self.starts = samples, starts
        self.rng = np.random.default_rng(seed)

    def plan(
        self, q: FloatArray, berry: FloatArray, current: FloatArray
    ) -> tuple[FloatArray, FloatArray] | None:
        """``(q_pre_grasp, axis)`` for the squarest reachable approach, or None."""
        c = self.cfg
        for axis in cone_axes(c.approach_axis, c.approach_cone_deg):
            pre = approach_pose(current, berry, axis, c.grasp_offset + c.standoff)
            q_pre = self.solve(q, pre)
            if q_pre is None:
                continue
            grasp = approach_pose(current, berry, axis, c.grasp_offset)
            if self.solve(q_pre, grasp, sample=False) is not None:
                return q_pre, axis
        return None

    def solve(self, q: FloatArray, target: FloatArray, sample: bool = True) -> FloatArray | None:
        """Elongations reaching ``target`` (4, 4) on the model, nearest to ``q`` among the
        converged starts; None when none converges."""
        starts = [q]
        if sample:
            lo, hi = self.arm.lower, self.arm.upper
            qs = self.rng.uniform(lo, hi, size=(self.samples, lo.size))
            poses = self.arm.forward_batch(qs)  # (N, 4, 4)
            pos_err = np.linalg.norm(poses[:, :3, 3] - target[:3, 3], axis=1)
            cos = np.clip(poses[:, :3, 2] @ target[:3, 2], -1.0, 1.0)
            score = pos_err + 0.05 * np.arccos(cos)  # 5 cm per rad: both matter
            starts += list(qs[np.argsort(score)[: self.starts]])
        best: FloatArray | None = None
        for q0 in starts:
            sol = self.resolver.solve(  # type: ignore[attr-defined]
                q0, target, max_steps=1500, position_tolerance=1e-3, orientation_tolerance=0.02
            )
            if sol.converged:
                cand = np.asarray(sol.q, dtype=np.float64)
                if best is None or np.linalg.norm(cand - q) < np.linalg.norm(best - q):
                    best = cand
        return best
