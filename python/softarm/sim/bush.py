"""A simulated blackberry bush: berries in front of the arm along +Y of the base frame
(redundancy paper, section IV-F), each carrying an ArUco tag (section IV-E), and canes
(branches) as cubic polynomial curves (planning paper, curve obstacles).

Every berry is reachable by construction: it is generated from the forward kinematics of
the arm given (the TRUE simulated arm, not the controller's model) at random feasible
elongations whose gripper points roughly along +Y, placed ``grasp_offset`` ahead of the
gripper along its approach axis. Canes run behind the berries (berries hang on the front
of a cane), and none comes near the straight approach line of any berry. Everything is a
function of the seed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softarm._core import PolynomialCurve, SoftArm
from softarm.checks import FloatArray
from softarm.errors import ParameterError
from softarm.geometry import APPROACH_CONE_DEG, cone_axes

__all__ = ["Berry", "Branch", "Bush"]

PLUS_Y = np.array([0.0, 1.0, 0.0])
#: Most berries a bush is generated with (`softarm harvest --berries` is bounded by it).
MAX_BERRIES = 40


@dataclass(frozen=True)
class Berry:
    """One berry: its tag id, centre (base frame, m), the gripper's approach axis at the
    generating configuration, that configuration ``q`` (m) and the ripeness in [0, 1]."""

    tag_id: int
    position: FloatArray
    approach: FloatArray
    q: FloatArray
    ripeness: float = 1.0

    def tag_pose(self, tilt_deg: float = 20.0) -> FloatArray:
        """``T_base_tag``: the tag centred on the berry, facing the arm (-Y), turned
        ``tilt_deg`` about +Z towards +X so the eye-to-hand camera also sees it; tag y up."""
        a = np.radians(tilt_deg)
        z = np.array([np.sin(a), -np.cos(a), 0.0])
        y = np.array([0.0, 0.0, 1.0])
        pose = np.eye(4)
        pose[:3, :3] = np.column_stack([np.cross(y, z), y, z])
        pose[:3, 3] = self.position
        return pose


@dataclass(frozen=True)
class Branch:
    """A cane: ``coeffs`` (3, 4) of a cubic in u ∈ [0, 1], ascending powers, row 0 = x(u)
    (the layout of ``softarm.PolynomialCurve``)."""

    coeffs: FloatArray

    def curve(self) -> PolynomialCurve:
        """The cane as a ``softarm.PolynomialCurve`` obstacle (planning paper eq. 10)."""
        return PolynomialCurve(self.coeffs, (0.0, 1.0))

    def points(self, n: int = 50) -> FloatArray:
        """(n, 3) points at evenly spaced u."""
        u = np.linspace(0.0, 1.0, n)
        return (self.coeffs @ np.vander(u, self.coeffs.shape[1], increasing=True).T).T


@dataclass(frozen=True)
class Bush:
    """Berries and branches; see the module docstring and :meth:`generate`."""

    berries: list[Berry]
    branches: list[Branch]
    seed: int
    extra: dict[str, float] = field(default_factory=dict)

    @classmethod
    def generate(
        cls,
        arm: SoftArm,
        n_berries: int,
        seed: int,
        *,
        grasp_offset: float = 0.03,
        max_tilt_deg: float = 20.0,
        min_spacing: float = 0.06,
        corridor: float = 0.15,
        branch_clearance: float = 0.045,
        first_tag: int = 10,
        unripe_fraction: float = 0.0,
        cone_deg: float = APPROACH_CONE_DEG,
        view_point: FloatArray | None = None,
        min_view_angle_deg: float = 3.0,
        limits: tuple[FloatArray, FloatArray] | None = None,
    ) -> Bush:
        """A bush of ``n_berries`` for ``arm`` (anything with ``lower``, ``upper`` and
        ``forward_batch``), deterministic in ``seed``.

        Generating elongations lie 10 % of the range inside the limits. A berry is
        accepted when its gripper axis is within ``max_tilt_deg`` of +Y and it
        is at least ``min_spacing`` from the others. Each gets one cane behind it, kept
        ``branch_clearance`` (centre line to centre line: the 25 mm gripper and a 5 mm cane
        leave 15 mm) away from every berry's approach corridor (``corridor``
        m in front of the berry to 2 cm behind it, along +Y and every axis within
        ``cone_deg`` of it: by default the harvest's default ``approach_cone_deg``,
        ``softarm.geometry.APPROACH_CONE_DEG``). With a ``view_point`` (the eye-to-hand
        camera), no two berries are within ``min_view_angle_deg`` of each other as seen
        from it: none hides another's tag, so every berry can be found. ``limits``
        (lower, upper) overrides the arm's own elongation limits (e.g. the true actuators'
        range at 0–70 psi).
        """
        if not 1 <= n_berries <= MAX_BERRIES:
            raise ParameterError(f"n_berries must be in [1, {MAX_BERRIES}], got {n_berries}")
        rng = np.random.default_rng(seed)
        lo, hi = limits or (arm.lower, arm.upper)
        lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        # Feasible with room: 10 % of the range off each limit (the paper's actuators work
        # at 10-60 of 70 psi), so the controller's model, a few % off, can reach them too.
        lower, upper = lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo)
        berries: list[Berry] = []
        for _ in range(200):
            qs = rng.uniform(lower, upper, size=(4000, lower.size))
            poses = arm.forward_batch(qs)
            ok = poses[:, :3, 2] @ PLUS_Y > np.cos(np.radians(max_tilt_deg))
            for i in np.flatnonzero(ok):
                pos = poses[i, :3, 3] + grasp_offset * poses[i, :3, 2]
                if any(np.linalg.norm(pos - b.position) < min_spacing for b in berries):
                    continue
                if view_point is not None and any(
                    _angle(pos - view_point, b.position - view_point) < min_view_angle_deg
                    for b in berries
                ):
                    continue
                ripe = 0.2 if rng.uniform() < unripe_fraction else 1.0
                tag = first_tag + len(berries)
                berries.append(Berry(tag, pos, poses[i, :3, 2].copy(), qs[i].copy(), ripe))
                if len(berries) == n_berries:
                    break
            if len(berries) == n_berries:
                break
        else:
            raise ParameterError(f"could not place {n_berries} berries {min_spacing} m apart")
        # Approach lines: along +Y and along every axis of the cone the planner may tilt to
        # (softarm.geometry.cone_axes), so no straight approach meets a cane.
        segments = [
            (b.position - corridor * a, b.position + 0.02 * a)
            for b in berries
            for a in cone_axes(PLUS_Y, cone_deg)
        ]
        branches = [_cane(rng, b, segments, branch_clearance) for b in berries]
        return cls(berries, [c for c in branches if c is not None], seed)


def _cane(
    rng: np.random.Generator,
    berry: Berry,
    corridors: list[tuple[FloatArray, FloatArray]],
    clearance: float,
) -> Branch | None:
    """A gently curved cane 5–8 cm behind ``berry`` (along +Y), roughly in the XZ plane,
    away from every approach corridor; None if 50 tries fail."""
    for _ in range(50):
        centre = berry.position + PLUS_Y * rng.uniform(0.05, 0.08)
        angle = rng.uniform(0, np.pi)
        direction = np.array([np.cos(angle), 0.0, np.sin(angle)])
        length = rng.uniform(0.15, 0.3)
        bend = rng.normal(0.0, 0.03, size=3) * np.array([1.0, 0.5, 1.0])
        wiggle = rng.normal(0.0, 0.01, size=3)
        # p(u) = start + u L d + u(1-u) bend + u(1-u)(2u-1) wiggle, u in [0, 1]
        start = centre - 0.5 * length * direction
        c0 = start
        c1 = length * direction + bend - wiggle
        c2 = -bend + 3 * wiggle
        c3 = -2 * wiggle
        branch = Branch(np.column_stack([c0, c1, c2, c3]))
        pts = branch.points(80)
        if all(_segment_distance(pts, a, b) >= clearance for a, b in corridors):
            return branch
    return None


def _angle(a: FloatArray, b: FloatArray) -> float:
    """Angle (deg) between two vectors."""
    c = a @ b / (np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def _segment_distance(points: FloatArray, a: FloatArray, b: FloatArray) -> float:
    """Smallest distance from ``points`` (n, 3) to the segment ab (a generator check)."""
    ab = b - a
    u = np.clip((points - a) @ ab / (ab @ ab), 0.0, 1.0)
    return float(np.min(np.linalg.norm(points - (a + u[:, None] * ab), axis=1)))
