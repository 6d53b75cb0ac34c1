"""The arm as one PyElastica Cosserat rod: three sections joined by their plates, the
actuators' elongations as intrinsic strains, gravity and the point masses as loads.

Layout along the rod (proximal first): section 0 (``elements_per_section`` elements over
its rest length), plate 0 (one element, the plate offset b_0), section 1, plate 1,
section 2. The distal plate and gripper (offset b_2, twist beta_2) are rigid beyond the
rod's tip. The rod is isotropic, so the twists need not twist its material frame:
Rot_z(beta) T_i(theta) = T_i(theta + beta) Rot_z(beta) (eq. 2), so section i bends towards
theta_i plus the twists before it and the end-effector frame is
``tip frame @ Trans_z(b_2) Rot_z(beta_0 + beta_1 + beta_2)``, eq. (3) rearranged.

Intrinsic strains of section i from its true elongations l (eq. 1):

* extension: the arc length is L_i + mean(l), so the rest stretch is mean(l) / L_i
  (``rest_sigma[2]``: PyElastica measures strains against the reference length L_i);
* bending: the bending angle phi_i = 2 s_i / (3 r_i) over the section, towards the
  direction theta_i of eq. (1) (away from the longest actuator); per reference length
  the rest curvature is phi_i / L_i about the axis z x (cos theta_i, sin theta_i, 0)
  = (-sin theta_i, cos theta_i, 0) of the section's base frame.

With no gravity and no masses the rod's equilibrium is exactly the constant-curvature
arm of eq. (1-3) (``tests/sim/test_cosserat.py`` checks it): the elements are the arc's
chords, with half a segment's bend where a section meets the clamped stub or a plate.

Stepping: :meth:`RodArm.relax` finds the static equilibrium (damped dynamics until every
node is slower than ``settle_speed``; used at the start), :meth:`RodArm.advance` runs the
damped dynamics in real time, one control period at a time (the plant). The translational
masses are the arm's; the rotational inertia of the 2-4 cm elements, and the mass of the
nodes next to a short stiff plate, are raised so that nothing vibrates faster than a
section's axial mode (a step of ~0.3 ms instead of ~0.01 ms; it changes only the
highest-frequency content, not the equilibrium or the slow bending modes). The damping
(uniform, ``damping`` 1/s) is an assumption: close to critical for the first bending mode.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

from softarm._core import SoftArm
from softarm.checks import FloatArray as F64
from softarm.errors import DivergenceError, NonFiniteError, ShapeError
from softarm.geometry import ACTUATOR_RADIUS
from softarm.sim.cosserat import require_elastica
from softarm.sim.cosserat.params import RodParameters

__all__ = ["RodArm"]


#: The clamped stub below the base plane (m) and its element kind.
_STUB = 0.01
_STUB_KIND = -100


def _rot_z(a: float) -> F64:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class _Elements:
    """The rod's elements, proximal first, and what each is made of.

    A clamped stub below the base (so that the first section element can tilt by half a
    segment, as an arc's first chord does), then section i (kind i, ``ne`` elements over
    its rest length), plate i (kind -1 - i, one element over the plate offset), ...,
    section n - 1; the distal plate is rigid beyond the tip. Plates and stub are 10 x
    their section's bending stiffness (rigid SLA resin); in everything else they count
    with the section before them (the stub with section 0).
    """

    length: F64
    kind: npt.NDArray[np.int_]
    section: npt.NDArray[np.int_]  # the section each element counts with
    ring_radius: F64
    line_mass: F64  # kg/m
    bend: F64  # EI
    twist: F64  # GJ
    axial: F64  # EA
    shear: F64  # GA

    @classmethod
    def of(cls, arm: SoftArm, p: RodParameters) -> _Elements:
        """The elements of ``arm`` with ``p``'s discretisation, masses and stiffness."""
        secs, ne = arm.sections, p.elements_per_section
        lengths, kinds = [_STUB], [_STUB_KIND]
        for i, s in enumerate(secs):
            lengths += [s.rest_length / ne] * ne
            kinds += [i] * ne
            if i < len(secs) - 1:
                lengths.append(s.offset)
                kinds.append(-1 - i)
        kind = np.array(kinds)
        sec_of = np.array([0 if k == _STUB_KIND else (k if k >= 0 else -1 - k) for k in kinds])
        ei_sec = p.stiffness(arm)
        r_ring = np.array([s.radius for s in secs])[sec_of]
        return cls(
            length=np.array(lengths),
            kind=kind,
            section=sec_of,
            ring_radius=r_ring,
            line_mass=p.line_masses(arm)[sec_of],
            bend=np.where(kind >= 0, 1.0, 10.0) * ei_sec[sec_of],
            twist=(2.0 * ei_sec[sec_of] / r_ring**2) * r_ring**2 / 3.0,
            axial=p.axial_stiffness(arm)[sec_of],
            shear=p.shear(arm)[sec_of],
        )

    def at_nodes(self, k: F64) -> F64:
        """A stiffness per element as one per Voronoi node (between two elements): the
        two half elements either side in series, so that a stiff stub or plate next to
        a section adds only its own (small) compliance."""
        ln = self.length
        rvl = 0.5 * (ln[1:] + ln[:-1])
        result: F64 = rvl / (0.5 * ln[1:] / k[1:] + 0.5 * ln[:-1] / k[:-1])
        return result


def _straight_rod(ea: Any, e: _Elements) -> Any:
    """The straight, unstrained rod along +z from the stub's foot, with the stiffness of
    ``e``. Its radius is the body's (ring + one muscle, as the clearance), its density the
    line mass spread over that disc; the shear and bend matrices carry the stiffness
    directly (Young's modulus 1)."""
    n = len(e.length)
    nodes = np.zeros((3, n + 1))
    nodes[2] = np.concatenate([[0.0], np.cumsum(e.length)]) - _STUB
    # The rod is isotropic, so its material frame need not twist at the plates:
    # Rz(beta) T_i(theta) = T_i(theta + beta) Rz(beta) (eq. 2), so section i bends
    # towards theta_i + the twists before it, and all twists turn the end effector
    # at the tip. (A 60 deg rest twist at one node would couple bending across it.)
    directors = np.repeat(np.eye(3)[:, :, None], n, axis=2)
    body = e.ring_radius + ACTUATOR_RADIUS
    density = e.line_mass / (math.pi * body**2)
    rod = ea.CosseratRod.straight_rod(
        n, nodes[:, 0].copy(), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]),
        float(nodes[2, -1] - nodes[2, 0]), body, density, youngs_modulus=1.0,
        position=nodes, directors=directors,
    )  # fmt: skip
    # Axial, shear and torsional stiffness (module docstring of params); the plates
    # and stub are stiffer in bending only.
    ga = e.shear
    rod.shear_matrix[:] = 0.0
    rod.shear_matrix[0, 0], rod.shear_matrix[1, 1], rod.shear_matrix[2, 2] = ga, ga, e.axial
    ei_v, gj_v = e.at_nodes(e.bend), e.at_nodes(e.twist)
    rod.bend_matrix[:] = 0.0
    rod.bend_matrix[0, 0], rod.bend_matrix[1, 1], rod.bend_matrix[2, 2] = ei_v, ei_v, gj_v
    return rod


def _point_masses(
    rod_mass: F64, e: _Elements, p: RodParameters, n_sections: int
) -> tuple[F64, float, float]:
    """The true node masses with the point masses added, the mass at the tip and its
    lever. A plate's mass goes to its element's two nodes; the distal plate, gripper
    and cube sit at the tip (their offset moment is a torque, ``_Weights``)."""
    true_mass = rod_mass.copy()
    for i in range(n_sections - 1):
        k = int(np.flatnonzero(e.kind == -1 - i)[0])
        true_mass[k : k + 2] += p.plate_masses[i] / 2
    tip_mass = p.plate_masses[-1] + p.gripper_mass + p.cube_mass
    true_mass[-1] += tip_mass
    moment = p.gripper_mass * p.gripper_com + p.cube_mass * p.cube_com
    lever = moment / tip_mass if tip_mass > 0 else 0.0
    return true_mass, tip_mass, lever


def _scale_inertia(rod: Any, e: _Elements, true_mass: F64) -> float:
    """Gives the rod fictitious inertia; returns its highest vibration frequency (rad/s).

    The relaxation only seeks the static equilibrium, which inertia does not change
    (gravity uses the true masses). A node or element whose springs would vibrate faster
    than a section's axial or shear mode, omega = 2 sqrt(k / (l m_elem)), gets mass or
    rotational inertia until it does not (Gershgorin: 2 sum(k) / m <= omega^2); short
    stiff plates and 1-2 cm elements' own rotational inertia would otherwise force a
    10-100x smaller step.
    """
    ln, ga = e.length, e.shear
    n = len(ln)
    m_elem = e.line_mass * ln
    sec_el = e.kind >= 0
    stiff = np.maximum(e.axial, ga)
    omega = float(np.max(2.0 * np.sqrt(stiff[sec_el] / ln[sec_el] / m_elem[sec_el])))
    k_ax = stiff / ln  # per element
    k_node = np.zeros(n + 1)
    k_node[:-1] += k_ax
    k_node[1:] += k_ax
    rod.mass[:] = np.maximum(true_mass, 2.0 * k_node / omega**2)
    ei_v, gj_v = e.at_nodes(e.bend), e.at_nodes(e.twist)
    k_rot_v = np.stack([ei_v, ei_v, gj_v]) / rod.rest_voronoi_lengths  # (3, n - 1)
    k_el = np.zeros((3, n))
    k_el[:, :-1] += k_rot_v
    k_el[:, 1:] += k_rot_v
    k_el[:2] += ga * ln / 2.0  # shear couples an element's turn to its nodes
    for k in range(n):
        jj = np.maximum(
            np.diag(rod.mass_second_moment_of_inertia[..., k]), 2.0 * k_el[:, k] / omega**2
        )
        rod.mass_second_moment_of_inertia[..., k] = np.diag(jj)
        rod.inv_mass_second_moment_of_inertia[..., k] = np.diag(1.0 / jj)
    return omega


def _bend_shares(kinds: npt.NDArray[np.int_], n_sections: int, ne: int) -> F64:
    """(n_sections, n_voronoi): the rotation (rad) per unit bending angle of each section
    at every Voronoi node (v between elements v and v + 1): 1/ne inside a section,
    1/(2 ne) where it meets the stub or a plate (a discrete arc's chords), 0 elsewhere."""
    share = np.zeros((n_sections, len(kinds) - 1))
    for v in range(len(kinds) - 1):
        a, b = kinds[v], kinds[v + 1]
        for i in range(n_sections):
            if a == i and b == i:
                share[i, v] = 1.0 / ne
            elif (a == i) != (b == i):
                share[i, v] = 0.5 / ne
    return share


class RodArm:
    """A Cosserat rod shaped like ``arm`` (the true, unloaded geometry).

    Args:
        arm: the geometry (radii, rest lengths, plate offsets, twists).
        params: masses, stiffness, discretisation and relaxation settings.
        gravity: (3,) gravity in the base frame (m/s^2).
    """

    def __init__(
        self, arm: SoftArm, params: RodParameters | None = None, gravity: Any = (0, 0, -9.81)
    ) -> None:
        ea = require_elastica()
        self.arm = arm
        self.params = p = params if params is not None else RodParameters()
        self.gravity = np.asarray(gravity, dtype=np.float64)
        if self.gravity.shape != (3,) or not np.all(np.isfinite(self.gravity)):
            raise ShapeError(f"gravity: expected 3 finite numbers, got {gravity!r}")
        secs = arm.sections
        elements = _Elements.of(arm, p)
        self.kinds = elements.kind
        # Section i bends towards theta_i plus the twists before it (_straight_rod).
        self._twist_before = np.concatenate([[0.0], np.cumsum([s.twist for s in secs])])
        rod = _straight_rod(ea, elements)
        true_mass, tip_mass, lever = _point_masses(rod.mass, elements, p, len(secs))
        self.true_mass = true_mass
        #: Highest vibration frequency (rad/s) after the scaling.
        self.omega_max = _scale_inertia(rod, elements, true_mass)
        self.dt = p.time_step if p.time_step is not None else 1.0 / self.omega_max
        self._bend_share = _bend_shares(elements.kind, len(secs), p.elements_per_section)
        rod.rest_kappa[:] = 0.0
        self._ne = p.elements_per_section
        self.rod = rod
        self.sim = self._simulation(ea, tip_mass, lever)
        self.stepper = ea.PositionVerlet()
        self.time = 0.0
        self.steps = 0
        self.elongation = np.zeros(arm.n_actuators)
        self._at_rest, self._rest_at = False, self.elongation.copy()

    def _simulation(self, ea: Any, tip_mass: float, lever: float) -> Any:
        """The rod clamped at the stub's foot, under the true weights (when there is
        gravity) and the uniform damping, finalised."""

        class Sim(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.Damping):  # type: ignore[misc]
            pass

        rod, sim = self.rod, Sim()
        sim.append(rod)
        sim.constrain(rod).using(
            ea.FixedConstraint, constrained_position_idx=(0, 1), constrained_director_idx=(0,)
        )
        if np.any(self.gravity != 0.0):
            sim.add_forcing_to(rod).using(
                _weights_class(ea), mass=self.true_mass, gravity=self.gravity,
                tip_weight=tip_mass * self.gravity, lever=lever,
            )  # fmt: skip
        sim.dampen(rod).using(
            ea.AnalyticalLinearDamper,
            uniform_damping_constant=self.params.damping,
            time_step=self.dt,
        )
        sim.finalize()
        return sim

    # --- intrinsic strains ----------------------------------------------------------

    def set_elongations(self, q: npt.ArrayLike) -> None:
        """Set the actuators' true elongations (m): the rest strains of eq. (1)."""
        l_all = np.asarray(q, dtype=np.float64)
        if l_all.shape != (self.arm.n_actuators,):
            raise ShapeError(f"q: expected shape ({self.arm.n_actuators},), got {l_all.shape}")
        if not np.all(np.isfinite(l_all)):
            raise NonFiniteError("q: contains NaN or inf")
        self.elongation = l_all.copy()
        conf = self.arm.configuration(l_all)  # per section: arc length, phi, theta (eq. 1)
        rod = self.rod
        sigma_z = np.zeros(len(self.kinds))
        kappa = np.zeros((3, len(self.kinds) - 1))
        for i, s in enumerate(self.arm.sections):
            arc, phi, theta = conf[i]
            # Elements are chords of the arc: length arc/ne x sinc(phi / (2 ne)).
            x = phi / (2 * self._ne)
            chord = 1.0 if x < 1e-8 else math.sin(x) / x
            sigma_z[self.kinds == i] = arc / s.rest_length * chord - 1.0
            angle = phi * self._bend_share[i] / rod.rest_voronoi_lengths
            direction = theta + self._twist_before[i]
            kappa[0] += -math.sin(direction) * angle
            kappa[1] += math.cos(direction) * angle
        rod.rest_sigma[2, :] = sigma_z
        rod.rest_kappa[:] = kappa

    # --- stepping -------------------------------------------------------------------

    def advance(self, duration: float) -> None:
        """Run the rod's damped dynamics for ``duration`` seconds of real time (the
        plant's stepping: the arm moves, lags and settles as a damped rod does). A rod
        already at rest under unchanged strains is not stepped."""
        if self._at_rest and np.array_equal(self.elongation, self._rest_at):
            return
        n = max(1, round(duration / self.dt))
        for _ in range(n):
            self.time = float(self.stepper.step(self.sim, self.time, self.dt))
        self.steps += n
        v = self.rod.velocity_collection
        if not np.all(np.isfinite(v)):
            raise DivergenceError("the Cosserat rod diverged (time step too large?)")
        self._at_rest = float(np.sqrt((v * v).sum(axis=0)).max()) < 0.1 * self.params.settle_speed
        self._rest_at = self.elongation.copy()

    def relax(self, max_time: float | None = None) -> float:
        """Run damped dynamics until every node is slower than ``settle_speed`` (checked
        every 100 steps) or ``max_time`` s; returns the fictitious time spent."""
        p = self.params
        limit = p.max_relax if max_time is None else max_time
        spent = 0.0
        while spent < limit:
            for _ in range(100):
                self.time = float(self.stepper.step(self.sim, self.time, self.dt))
            self.steps += 100
            spent += 100 * self.dt
            v = self.rod.velocity_collection
            if not np.all(np.isfinite(v)):
                raise DivergenceError("the Cosserat rod diverged (time step too large?)")
            if float(np.sqrt((v * v).sum(axis=0)).max()) < p.settle_speed:
                break
        return spent

    # --- read-out -------------------------------------------------------------------

    def centreline(self) -> F64:
        """Node positions (n_nodes, 3) of the rod from the base (origin) to the tip."""
        result: F64 = self.rod.position_collection[:, 1:].T.copy()
        return result

    def node_sections(self) -> npt.NDArray[np.int64]:
        """Section index of every node of :meth:`centreline` (the node ending an element;
        plates count with the section before them)."""
        k = self.kinds
        sec = np.where(k >= 0, k, -1 - k)
        return np.concatenate([[0], sec[1:]])

    def tip_frame(self) -> F64:
        """(4, 4) pose of the rod's tip (the distal section's end plate). The last
        element is the arc's last chord, half a segment short of the end tangent: turn
        it on by half the bend of the last Voronoi node."""
        out = np.eye(4)
        half = 0.5 * self.rod.kappa[:, -1] * self.rod.rest_voronoi_lengths[-1]
        turn = Rotation.from_rotvec(half).as_matrix()  # in the element's own frame
        out[:3, :3] = self.rod.director_collection[..., -1].T @ turn
        out[:3, 3] = self.rod.position_collection[:, -1]
        return out

    def pose(self) -> F64:
        """End-effector pose (4, 4): the tip, then the rigid gripper (eq. 3's b_3), turned
        by all the twists (see the module docstring)."""
        off = np.eye(4)
        off[:3, :3] = _rot_z(float(self._twist_before[-1]))  # every twist (module docstring)
        off[2, 3] = self.arm.sections[-1].offset
        return self.tip_frame() @ off


def _weights_class(ea: Any) -> type:
    """A forcing with the true weights: every node's mass x gravity, and the moment of
    the gripper's and cube's weight about the tip (their lever along the tip's axis)."""

    class _Weights(ea.NoForces):  # type: ignore[misc]
        def __init__(self, mass: F64, gravity: F64, tip_weight: F64, lever: float) -> None:
            super().__init__()
            self.force = np.outer(np.asarray(gravity, dtype=float), mass)  # (3, n_nodes)
            self.tip_weight, self.lever = np.asarray(tip_weight, dtype=float), float(lever)

        def apply_forces(self, system: Any, time: float = 0.0) -> None:
            system.external_forces += self.force

        def apply_torques(self, system: Any, time: float = 0.0) -> None:
            q = system.director_collection[..., -1]
            tau = np.cross(self.lever * q[2], self.tip_weight)  # lab frame
            system.external_torques[:, -1] += q @ tau  # material frame

    return _Weights
