"""Placement planning on the controller's model, before the loop closes on the cameras.

The resolver is a local method: from the straight ready pose, a target 90° away (the
gripper turns from +Z to face the bush along +Y) can leave it stuck on the joint limits,
and not every berry can be faced exactly along +Y. So placement first solves on the model:
for approach axes in a cone around +Y (squarest first), from several starts (the current
command and the best of a seeded batch of random configurations, scored by forward
kinematics), it looks for elongations reaching the pre-grasp pose AND the grasp pose.
The machine ramps the actuators to that solution, then servos on the cameras (eq. 22).

With known canes (curve obstacles, as in the planning paper) a solution is kept only if
the model arm clears them by ``margin`` all along the straight actuator-space ramp to it,
along the final approach to the berry and at the grasp.

With a ``band`` (``[harvest] plan_band``, off by default), each solution is first moved
along its pose's null space so that the actuator nearest a limit has as much room as the
pose allows (:mod:`.mid_band`): a regulator driven towards 0 or 70 psi cannot be driven
harder, and on a slow plant that one channel sets the time of a move. Measured on the
slow plant's fresh seeds, it did not make the berries quicker (docs/harvest-candidates.md,
"Pre-grasp poses off the limits").
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence

import numpy as np

from softarm._core import Resolver, SoftArm
from softarm.checks import FloatArray
from softarm.geometry import cone_axes
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.mid_band import toward_mid
from softarm.harvest.machine.targets import approach_pose
from softarm.harvest_config import HarvestConfig

__all__ = ["SOLVE_STEPS", "ModelIK", "cone_axes", "planning_resolver"]


#: The planner's last pass: a via configuration off the approach line (:meth:`ModelIK._detour`).
DETOUR = -1.0
#: How many candidate detours (clear themselves) have their two ramps checked, shortest first.
DETOUR_CHECKS = 40


def planning_resolver(model: SoftArm, joint_limit_gain: float = -1e-3) -> Resolver:
    """A hybrid resolver for planning on ``model``: the default gains with a joint-limit
    gain (γ₅ of eq. 20, on the cost of eq. 14) 500 times the closed-loop one, so solutions
    sit mid-range, where the true arm (a few % off the model) can still reach them."""
    gains = Resolver(model, mode="hybrid").gains.replace(hybrid_gamma=joint_limit_gain)
    return Resolver(model, mode="hybrid", gains=gains)


#: The most resolver steps one start of :meth:`ModelIK.solve` runs. A start that reaches
#: its pose converges within a few dozen steps (at most 63 of the 1,749 that converged on
#: diagnosis seeds 1410-1413, tag world, and 90155, row); one that does not runs to the
#: cap, and at a cap of 1,500 those were 99 % of the IK's time on row 90155. Only
#: converged starts are used, so the plans are the same wherever no start would have
#: converged past the cap.
SOLVE_STEPS = 300


class ModelIK:
    """Implements :class:`~softarm.harvest.machine.interfaces.PlacementPlanner`.

    Args:
        resolver: a ``softarm.Resolver`` on the model (its ``solve`` refines each start),
            best from :func:`planning_resolver`.
        config: the machine's configuration (approach axis and cone, offsets).
        samples: random configurations scored per axis.
        starts: how many of the best-scored ones are refined (plus the current command).
        seed: seed of the random configurations.
        clearance: the model arm's gap to the known canes; None = no obstacles.
        margin: smallest gap (m) accepted on the final approach (closed loop, on the
            approach line).
        ramp_margin: smallest gap (m) accepted along the open-loop ramps: before the loop
            closes the true arm is off the model by up to a few cm.
        via: how much further back (m) than the pre-grasp pose the via point lies.
        limit_room: smallest distance (m) of the grasp solution to the joint limits, so
            that the true arm (gains and geometry a few % off the model) can still reach
            the berry within a millimetre in closed loop.
        band: each solution is moved in its task's null space towards the middle of
            every actuator's range, out of this fraction of it at either end
            (:func:`~softarm.harvest.control.mid_band.toward_mid`), the unmoved solutions
            kept as a fallback; 0: solutions as the resolver leaves them.
        near_standoff: a pre-grasp distance (m) tried before ``config.standoff`` on every
            axis and pass; 0 (or not below the standoff): the standoff alone
            (:func:`~softarm.harvest.control.stack.build_control_stack` gives the config's
            ``near_standoff`` for berries fixed by their tags).
    """

    def __init__(
        self,
        resolver: Resolver,
        config: HarvestConfig,
        samples: int = 3000,
        starts: int = 4,
        seed: int = 0,
        clearance: Clearance | None = None,
        margin: float = 0.01,
        ramp_margin: float = 0.025,
        via: float = 0.1,
        limit_room: float = 0.001,
        band: float = 0.0,
        near_standoff: float = 0.0,
    ) -> None:
        self.resolver = resolver
        self.arm = resolver.arm
        self.cfg = config
        self.samples, self.starts = samples, starts
        self.rng = np.random.default_rng(seed)
        self.clearance, self.margin, self.via = clearance, margin, via
        self.ramp_margin = ramp_margin
        self.limit_room = limit_room
        self.band = band
        self.near_standoff = near_standoff
        #: The canes to plan around where no plan clears ``clearance``'s: the ones C1
        #: saw itself, once C2's survey has added its own (ControlStack.know_canes).
        self.fallback: Clearance | None = None
        #: Whether the last plan cleared only the fallback's canes.
        self.fell_back = False
        #: The pre-grasp distance (m) short of the grasp pose of the last plan:
        #: ``near_standoff`` where a plan that near keeps the margins, else ``standoff``.
        self.standoff = config.standoff
        #: Told after each plan whether it fell back (ControlStack.know_canes: the loop
        #: then follows it with the canes it cleared).
        self.on_plan: Callable[[bool], None] | None = None

    def fall_back_on(self, fallback: Clearance, on_plan: Callable[[bool], None]) -> None:
        """Where no plan clears the canes of a refined map, plan around ``fallback``'s
        (the canes known before); ``on_plan(fell_back)`` after each plan."""
        self.fallback = fallback
        self.on_plan = on_plan

    def plan(
        self,
        q: FloatArray,
        berry: FloatArray,
        current: FloatArray,
        avoid: Sequence[FloatArray] = (),
    ) -> tuple[list[FloatArray], FloatArray] | None:
        """``(waypoints, axis)`` for the squarest reachable approach whose ramp is clear:
        straight to the pre-grasp pose if possible, else via a pose ``via`` further back
        on the approach line (the arm then enters the bush along that line). Preferred:
        grasps three times ``limit_room`` from the joint limits (pre-grasp ``limit_room``)
        and ramps ``ramp_margin`` from the canes; then grasps ``limit_room`` from the
        limits; then a via half as far back; then grasps on the limits. Every pass keeps
        the same cane margins. A berry with no such plan is UNREACHABLE: brushing a cane
        open loop is not worth one berry. The axes in ``avoid`` (within 1°) are skipped:
        the true arm could not reach the berry along them.

        With a ``fallback``, a berry that no plan clear of every cane reaches is planned
        clear of the fallback's canes, C1's own, as it is without C2's survey
        (``fell_back``): a phantom among the survey's canes would otherwise cost the
        berry. ``on_plan`` is told whether it fell back."""
        self.fell_back = False
        found = self._plan(q, berry, current, avoid)
        if found is None and self.fallback is not None and self.clearance is not None:
            every, self.clearance = self.clearance, self.fallback
            try:
                found = self._plan(q, berry, current, avoid)
            finally:
                self.clearance = every
            self.fell_back = found is not None
        if self.on_plan is not None:
            self.on_plan(self.fell_back)
        return found

    def _plan(
        self,
        q: FloatArray,
        berry: FloatArray,
        current: FloatArray,
        avoid: Sequence[FloatArray],
    ) -> tuple[list[FloatArray], FloatArray] | None:
        tried = np.asarray(avoid, dtype=np.float64).reshape(-1, 3)
        axes = [
            a
            for a in cone_axes(self.cfg.approach_axis, self.cfg.approach_cone_deg)
            if not np.any(tried @ a > np.cos(np.radians(1.0)))
        ]
        passes = [  # (joint-limit room at the grasp, gap along the ramps, via points)
            (3 * self.limit_room, self.ramp_margin, (None, self.via)),
            (self.limit_room, self.ramp_margin, (None, self.via)),
            # A via point half as far back: it enters the bush on a shorter line
            # where the long one leaves the arm's reach (same margins; seed 502's berry 12).
            (self.limit_room, self.ramp_margin, (0.5 * self.via,)),
            # Then a grasp on the joint limits: the loop may fall short by the model's
            # error there, but the canes keep the same margins (seed 500's berry 10).
            (0.0, self.ramp_margin, (None, self.via, 0.5 * self.via)),
            # Last, a detour: the straight ramp to a pre-grasp pose passes too near a
            # cane, so the arm goes round it through a configuration of its own (same
            # margins; seed 641's berry 12).
            (self.limit_room, self.ramp_margin, (DETOUR,)),
        ]
        for room, ramp, vias in passes:
            for via in vias:
                for axis, standoff in itertools.product(axes, self._standoffs()):
                    path = self._path(q, berry, current, axis, via, room, ramp, standoff)
                    if path is not None:
                        self.standoff = standoff
                        return path, axis
        return None

    def _standoffs(self) -> tuple[float, ...]:
        """The pre-grasp distances to try, nearest first: ``near_standoff`` (when set) saves
        fine positioning and the back-out part of their way on a slow plant, where the
        margins allow it; ``standoff`` everywhere else."""
        near, standoff = self.near_standoff, self.cfg.standoff
        return (near, standoff) if 0.0 < near < standoff else (standoff,)

    def _path(
        self,
        q: FloatArray,
        berry: FloatArray,
        current: FloatArray,
        axis: FloatArray,
        via: float | None,
        room: float,
        ramp: float,
        standoff: float,
    ) -> list[FloatArray] | None:
        c = self.cfg
        pre = approach_pose(current, berry, axis, c.grasp_offset + standoff)
        grasp = approach_pose(current, berry, axis, c.grasp_offset)
        for q_pre in self.solve(q, pre):
            q_grasp = self.solve(q_pre, grasp, sample=False)
            if not q_grasp or self._room(q_grasp[0]) < room:
                continue  # the true arm differs by a few %: grasp away from the limits
            if room > self.limit_room and self._room(q_pre) < self.limit_room:
                continue
            if not self.clear(q_pre, q_grasp[0], 5, self.margin):
                continue
            if via == DETOUR:
                q_mid = self._detour(q, q_pre, ramp)
                if q_mid is not None:
                    return [q_mid, q_pre]
                continue
            if via is None:
                if self.clear(q, q_pre, 12, ramp):
                    return [q_pre]
                continue
            back = approach_pose(current, berry, axis, c.grasp_offset + standoff + via)
            for q_via in self.solve(q_pre, back, sample=False) + self.solve(q, back):
                if self.clear(q, q_via, 12, ramp) and self.clear(q_via, q_pre, 6, ramp):
                    return [q_via, q_pre]
        return None

    def _detour(self, q: FloatArray, q_pre: FloatArray, ramp: float) -> FloatArray | None:
        """A configuration through which both straight ramps, ``q`` → it → ``q_pre``,
        keep ``ramp`` from the canes on the model: the shortest such way (in actuator
        space) among ``samples`` random configurations of the joint box; None if none."""
        if self.clearance is None:
            return None  # no canes: the straight ramp was clear
        if min(self.clearance.gap(q), self.clearance.gap(q_pre)) < ramp:
            return None  # no way in keeps the margin where it starts or ends
        lo, hi = self.arm.lower, self.arm.upper
        mids = self.rng.uniform(lo, hi, size=(self.samples, lo.size))
        length = np.linalg.norm(mids - q, axis=1) + np.linalg.norm(mids - q_pre, axis=1)
        tried = 0
        for k in np.argsort(length):
            q_mid = mids[k]
            if self.clearance.gap(q_mid) < ramp:
                continue
            tried += 1
            if self.clear(q, q_mid, 12, ramp) and self.clear(q_mid, q_pre, 12, ramp):
                return np.asarray(q_mid, dtype=np.float64)
            if tried >= DETOUR_CHECKS:
                break
        return None

    def _room(self, q: FloatArray) -> float:
        """Distance (m) of ``q`` to the nearest joint limit."""
        return float(min(np.min(q - self.arm.lower), np.min(self.arm.upper - q)))

    def clear(
        self, q0: FloatArray, q1: FloatArray, steps: int = 12, margin: float | None = None
    ) -> bool:
        """Whether the model arm keeps ``margin`` (default: the open-loop ``ramp_margin``)
        from the canes along the actuator-space line from ``q0`` to ``q1``."""
        if self.clearance is None:
            return True
        need = self.ramp_margin if margin is None else margin
        return self.clearance.path_gap(q0, q1, steps) >= need

    def solve(self, q: FloatArray, target: FloatArray, sample: bool = True) -> list[FloatArray]:
        """Elongations reaching ``target`` (4, 4) on the model from each start that
        converges, nearest to ``q`` first; [] when none does. With a ``band``, each moved
        towards mid-range in its pose's null space comes first (those it could move), then
        the solutions as the resolver left them: a moved one whose ramp or approach comes
        nearer a cane than the pass allows leaves the unmoved one to try."""
        starts = [q]
        if sample:
            lo, hi = self.arm.lower, self.arm.upper
            qs = self.rng.uniform(lo, hi, size=(self.samples, lo.size))
            poses = self.arm.forward_batch(qs)  # (N, 4, 4)
            pos_err = np.linalg.norm(poses[:, :3, 3] - target[:3, 3], axis=1)
            cos = np.clip(poses[:, :3, 2] @ target[:3, 2], -1.0, 1.0)
            score = pos_err + 0.05 * np.arccos(cos)  # 5 cm per rad: both matter
            starts += list(qs[np.argsort(score)[: self.starts]])
        found = []
        for q0 in starts:
            sol = self.resolver.solve(
                q0, target, max_steps=SOLVE_STEPS, position_tolerance=1e-3,
                orientation_tolerance=0.02,
            )  # fmt: skip
            if sol.converged:
                found.append(np.asarray(sol.q, dtype=np.float64))
        found.sort(key=lambda x: float(np.linalg.norm(x - q)))
        if self.band <= 0:
            return found
        mask = self.resolver.gains.axis_mask
        moved = [toward_mid(self.arm, x, target, mask, self.band) for x in found]
        return [m for m, x in zip(moved, found, strict=True) if m is not x] + found
