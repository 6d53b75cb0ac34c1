"""Physical parameters of the Cosserat-rod arm: masses, stiffness, discretisation.

Nothing here needs PyElastica: the numbers and the Euler-Bernoulli design of the stiffness
are plain numpy, so they can be checked and documented without the optional extra.
``docs/fidelity.md`` lists every number with its source; in short:

* The redundancy paper gives the geometry (section II-A, eq. 1-3) but no mass and no
  stiffness. The masses are estimates from the listed parts (silicone core, 5/8" braided
  sleeve, SLA plugs, clamps, push-to-connect fitting per muscle; SLA plates; the SG90
  servo, three urethane fingers, the NIR sensor and the eye-in-hand camera in the
  gripper; the marker cube).
* The bending stiffness is *chosen* (as the issue asks) so that the straight arm held
  horizontal sags 3 cm at the gripper, the middle of 1-5 cm: :func:`design_stiffness`
  solves the Euler-Bernoulli cantilever for it.
* Shear and torsion: the muscles as a ring of n fibres at the section's actuator radius
  r (n = 6 in the paired proximal and medial sections, 3 in the distal one) give
  I = n A r^2 / 2, so n E A = 2 EI / r^2; with G = E / 3 (incompressible rubber,
  Poisson 0.5) the shear stiffness is GA = 27/28 x (2 EI / r^2) / 3 (PyElastica's
  Timoshenko factor) and GJ = (2 EI / r^2) r^2 / 3.
* Axial stiffness: a pressurised McKibben muscle is far softer along its axis than
  its fibres; ``muscle_axial_stiffness`` (N/m of one 15 cm muscle, an estimate of a
  few N/mm) gives EA = n k L for the section.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from softarm._core import SoftArm
from softarm.checks import FloatArray as F64
from softarm.errors import ParameterError

__all__ = ["RodParameters", "cantilever_sag", "design_stiffness"]


#: Muscles per section, proximal first (paper II-A: three pairs, three pairs, three).
MUSCLES = (6, 6, 3)


@dataclass(frozen=True)
class RodParameters:
    """Masses (kg), stiffness and discretisation of the rod arm.

    ``bending_stiffness`` (N m^2) is per section; ``None`` designs it with
    :func:`design_stiffness` for ``design_sag`` at the gripper, arm horizontal.
    """

    #: One pneumatic muscle with its plugs, clamps and fitting (estimate, kg).
    muscle_mass: float = 0.035
    #: End plate of each section, proximal first (SLA resin, estimate, kg).
    plate_masses: tuple[float, ...] = (0.050, 0.040, 0.030)
    #: Gripper: servo 9 g, fingers, NIR sensor, eye-in-hand camera (estimate, kg).
    gripper_mass: float = 0.120
    #: Its centre of mass beyond the distal plate (m): half the 60 mm gripper offset.
    gripper_com: float = 0.030
    #: The marker cube (estimate, kg) and its centre beyond the distal plate (m): the
    #: simulated rig's cube sits 5 cm behind the 60 mm gripper frame.
    cube_mass: float = 0.040
    cube_com: float = 0.010
    #: Gripper sag (m) of the straight arm held horizontal that fixes the stiffness.
    design_sag: float = 0.03
    #: Bending stiffness per section (N m^2); None: designed for ``design_sag``.
    bending_stiffness: tuple[float, ...] | None = None
    #: Axial stiffness of one muscle (N/m over its length; estimate, a few N/mm).
    muscle_axial_stiffness: float = 3000.0
    #: Shear stiffness GA per section (N); None: the ring-of-muscles value.
    shear_stiffness: tuple[float, ...] | None = None
    #: Elements per section (the plates are one element each).
    elements_per_section: int = 4
    #: Standard gravity (m/s^2), only for the stiffness design.
    g: float = 9.81
    #: Relaxation each control period: time step (s; None: 1 / the rod's highest axial
    #: frequency, half the position Verlet stability limit), uniform damping (1/s), and
    #: the settled criterion: node speeds below ``settle_speed`` (m/s), at most
    #: ``max_relax`` seconds of fictitious time.
    time_step: float | None = None
    damping: float = 40.0
    settle_speed: float = 5e-4
    max_relax: float = 0.5
    muscles: tuple[int, ...] = field(default=MUSCLES)

    def __post_init__(self) -> None:
        for name in ("muscle_mass", "design_sag", "damping", "muscle_axial_stiffness"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ParameterError(f"RodParameters.{name} = {v!r}: must be positive")
        for name in ("gripper_mass", "cube_mass", "settle_speed"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ParameterError(f"RodParameters.{name} = {v!r}: must be >= 0")
        if self.time_step is not None and not (
            math.isfinite(self.time_step) and self.time_step > 0
        ):
            raise ParameterError(f"RodParameters.time_step = {self.time_step!r}: must be > 0")
        if not (isinstance(self.elements_per_section, int) and self.elements_per_section >= 2):
            raise ParameterError("RodParameters.elements_per_section: must be an integer >= 2")

    def line_masses(self, arm: SoftArm) -> F64:
        """Mass per metre (kg/m) of each section's muscles."""
        return np.array(
            [
                n * self.muscle_mass / s.rest_length
                for n, s in zip(self.muscles, arm.sections, strict=True)
            ]
        )

    def stiffness(self, arm: SoftArm) -> F64:
        """Bending stiffness EI (N m^2) per section: given, or designed."""
        if self.bending_stiffness is not None:
            ei = np.asarray(self.bending_stiffness, dtype=float)
            if ei.shape != (arm.n_sections,) or not np.all(ei > 0):
                raise ParameterError("RodParameters.bending_stiffness: one positive per section")
            return ei
        return design_stiffness(arm, self)

    def axial_stiffness(self, arm: SoftArm) -> F64:
        """EA (N) per section: n muscles of stiffness k over the rest length L."""
        return np.array(
            [
                n * self.muscle_axial_stiffness * s.rest_length
                for n, s in zip(self.muscles, arm.sections, strict=True)
            ]
        )

    def shear(self, arm: SoftArm) -> F64:
        """GA (N) per section: given, or the ring of muscles' 27/28 (2 EI / r^2) / 3."""
        if self.shear_stiffness is not None:
            return np.asarray(self.shear_stiffness, dtype=float)
        r = np.array([s.radius for s in arm.sections])
        result: F64 = (27.0 / 28.0) * (2.0 * self.stiffness(arm) / r**2) / 3.0
        return result

    def with_stiffness(self, arm: SoftArm) -> RodParameters:
        """A copy with the designed stiffness fixed (so perturbed arms keep it)."""
        return replace(self, bending_stiffness=tuple(self.stiffness(arm).tolist()))


def _loads(arm: SoftArm, p: RodParameters) -> tuple[F64, F64, F64, float]:
    """Section boundaries along the straight arm (m), distributed line weight (N/m) per
    section, and the point weights (N) with their positions; the rod's length."""
    edges, x = [0.0], 0.0
    pts, wts = [], []
    line = p.line_masses(arm) * p.g
    for i, s in enumerate(arm.sections):
        x += s.rest_length
        edges.append(x)
        if i < arm.n_sections - 1:
            pts.append(x + s.offset / 2)  # the plate's centre
            wts.append(p.plate_masses[i] * p.g)
            x += s.offset
            edges.append(x)
    rod_len = x
    pts += [rod_len, rod_len + p.gripper_com, rod_len + p.cube_com]
    wts += [p.plate_masses[-1] * p.g, p.gripper_mass * p.g, p.cube_mass * p.g]
    return np.array(edges), line, np.array([pts, wts]), rod_len


def cantilever_sag(arm: SoftArm, p: RodParameters, ei: F64, samples: int = 4001) -> float:
    """Euler-Bernoulli deflection (m) of the gripper frame of the straight arm held
    horizontal, clamped at the base: w = int_0^L M(s) / EI(s) (L_ee - s) ds, with M the
    moment of every weight beyond s (small deflections). Plates are rigid."""
    edges, line, (pts, wts), rod_len = _loads(arm, p)
    ee = rod_len + arm.sections[-1].offset
    s = np.linspace(0.0, rod_len, samples)
    # distributed weight of the muscles only over the sections (not the plates)
    k_sec = np.minimum(np.searchsorted(edges, s, side="right") - 1, len(edges) - 2)
    in_section = k_sec % 2 == 0
    q = np.where(in_section, line[np.minimum(k_sec // 2, len(line) - 1)], 0.0)
    # M(s) = sum of point weights beyond s x lever + integral of q beyond s x lever
    m_pts = np.sum(np.clip(pts[None, :] - s[:, None], 0.0, None) * wts[None, :], axis=1)
    qx = q * s
    ds = s[1] - s[0]
    cum_q = np.cumsum(q[::-1])[::-1] * ds
    cum_qx = np.cumsum(qx[::-1])[::-1] * ds
    moment = m_pts + cum_qx - s * cum_q
    flex = np.where(in_section, 1.0 / ei[np.minimum(k_sec // 2, len(ei) - 1)], 0.0)
    integrand = moment * flex * (ee - s)
    return float(np.trapezoid(integrand, s))


def design_stiffness(arm: SoftArm, p: RodParameters) -> F64:
    """EI per section (N m^2) proportional to n r^2 (the ring of muscles) scaled so
    that :func:`cantilever_sag` is ``p.design_sag``. The sag is linear in 1/EI, so one
    evaluation at unit scale gives the scale."""
    shape = np.array([n * s.radius**2 for n, s in zip(p.muscles, arm.sections, strict=True)])
    shape = shape / shape[0]
    result: F64 = shape * cantilever_sag(arm, p, shape) / p.design_sag
    return result
