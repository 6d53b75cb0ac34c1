"""The calibrated model's parameters and the analytic Jacobian of its poses.

Parameters, per section i (proximal first): radius r_i, rest length L_i, plate offset b_i
and twist beta_i (eq. 1-3), then one gain g_m per actuator (true elongation = g_m x
command). The solver sees them as dimensionless deviations from the nominal arm so that
every column of the Jacobian has a comparable scale:

    r_i = r0_i (1 + x),  L_i = L0_i (1 + x),  b_i = b0_i + s_b x,  beta_i = beta0_i + x,
    g_m = 1 + x,  and optionally (``bias``) o_i = 0.1 m (x_1 e_1 + x_2 e_2),

the last a zero-mean elongation offset per section (true elongation = g c + o), a
constant bending bias: the gravity-aware term.

with ``s_b = max(|b0_i|, 1 cm)`` (a zero nominal offset still gets a length scale).

Every derivative is analytic, from the core's Jacobian (eq. 4-6) by the chain rule; no
finite differences:

* gain g_m: the pose depends on g_m only through l_m = g_m c_m + o_m, so
  d/dg_m = J[:, m] c_m; bias: d/dx = J_i (0.1 m e_k).
* rest length L_i: in eq. (1) the arc length (3 L0 + l_1 + l_2 + l_3) / 3 is the only place
  L0 enters (s_i and theta_i see only differences of the l's), so raising L_i by d equals
  raising the section's three elongations by d: d/dL_i = J_i [1, 1, 1].
* radius r_i: phi_i = 2 s_i / (3 r_i) and lambda_i phi_i = arc length; scaling r_i by
  (1 + e) equals scaling the elongations' deviations from their mean, l - mean(l), by
  1 / (1 + e) (s_i is homogeneous of degree 1 in them, theta_i of degree 0, the mean
  unchanged): d/dr_i = J_i (-(l_i - mean(l_i)) / r_i).
* offset b_i: Trans_z(b_i) in eq. (3) moves everything after it along z_{i+1}, the z axis
  of the next section's base frame: twist (v, w) = (z_{i+1}, 0).
* twist beta_i: Rot_z(beta_i) turns everything after it about that axis through that
  frame's origin o_{i+1}: (v, w) = (z_{i+1} x (p_EE - o_{i+1}), z_{i+1}).

(v, w) are the core Jacobian's convention: v = dp_EE, w the spatial (base-frame) angular
velocity, dR = [w] R. The test ``tests/calibration/test_model.py`` checks every column
against central differences.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm._core import Section, SoftArm
from softarm.checks import FloatArray as F64

__all__ = ["GEOMETRY_NAMES", "ParameterMap"]


#: The geometric parameters of one section, in the order of the parameter vector.
GEOMETRY_NAMES = ("radius", "rest_length", "offset", "twist")
#: Smallest length scale (m) of an offset parameter.
_MIN_OFFSET_SCALE = 0.01
#: Length scale (m) of a bending-bias parameter (gravity bends a section by a few mm of
#: actuator difference).
BIAS_SCALE = 0.1
#: Orthonormal basis of a section's zero-mean elongation offsets.
_BIAS_BASIS = np.array([[2.0, -1.0, -1.0], [0.0, 1.0, -1.0]]) / np.array(
    [[np.sqrt(6.0)], [np.sqrt(2.0)]]
)


@dataclass(frozen=True)
class ParameterMap:
    """Maps the parameter vector ``x`` to a :class:`SoftArm` and actuator gains.

    ``x`` holds 4 geometric deviations per section (``GEOMETRY_NAMES``) then one gain
    deviation per actuator; ``x = 0`` is the nominal arm with unit gains.
    """

    nominal: SoftArm
    #: Fit a bending bias per section (the gravity-aware term, see ``offsets``).
    bias: bool = False

    @property
    def n_sections(self) -> int:
        return int(self.nominal.n_sections)

    @property
    def n_actuators(self) -> int:
        return int(self.nominal.n_actuators)

    @property
    def size(self) -> int:
        return 4 * self.n_sections + self.n_actuators + (2 * self.n_sections if self.bias else 0)

    def names(self) -> list[str]:
        """A readable name for every entry of ``x``."""
        geo = [f"sections[{i}].{g}" for i in range(self.n_sections) for g in GEOMETRY_NAMES]
        bias = [f"sections[{i}].bias_{a}" for i in range(self.n_sections) for a in "xy"]
        gains = [f"actuator_gain[{m}]" for m in range(self.n_actuators)]
        return geo + gains + (bias if self.bias else [])

    def offsets(self, x: F64) -> F64:
        """Actuator elongation offsets (n,) of ``x`` (true elongation = gain x command +
        offset). Only their deviations from the section mean are fitted (a common
        offset *is* a rest-length change, eq. 1): two per section, along the orthonormal
        basis ``_BIAS_BASIS``, scaled by ``BIAS_SCALE``. A constant bending bias is the
        first-order effect of gravity on a section whose load changes little."""
        if not self.bias:
            return np.zeros(self.n_actuators)
        b = x[4 * self.n_sections + self.n_actuators :].reshape(self.n_sections, 2)
        result: F64 = (BIAS_SCALE * b @ _BIAS_BASIS).ravel()
        return result

    def offset_scales(self) -> F64:
        return np.array(
            [max(abs(s.offset), _MIN_OFFSET_SCALE) for s in self.nominal.sections], dtype=float
        )

    def arm(self, x: F64) -> SoftArm:
        """The arm of parameters ``x``. Its limits are the nominal *command* limits
        scaled by the section's largest gain (and shifted by its offsets), so that any
        command inside the nominal limits maps to elongations inside the fitted arm's."""
        geo = x[: 4 * self.n_sections].reshape(self.n_sections, 4)
        gains = self.gains(x).reshape(self.n_sections, 3)
        offs = self.offsets(x).reshape(self.n_sections, 3)
        sb = self.offset_scales()
        sections = []
        for i, s in enumerate(self.nominal.sections):
            dr, dl, db, dt = geo[i]
            lo, hi = float(np.min(gains[i])), float(np.max(gains[i]))
            sections.append(
                Section(
                    radius=s.radius * (1.0 + dr),
                    rest_length=s.rest_length * (1.0 + dl),
                    lower=s.lower * (lo if s.lower >= 0 else hi) + float(offs[i].min()),
                    upper=s.upper * (hi if s.upper >= 0 else lo) + float(offs[i].max()),
                    offset=s.offset + sb[i] * db,
                    twist=s.twist + dt,
                )
            )
        return SoftArm(sections)

    def gains(self, x: F64) -> F64:
        """Actuator gains (n,) of parameters ``x``."""
        return 1.0 + x[4 * self.n_sections : 4 * self.n_sections + self.n_actuators]

    def elongations(self, x: F64, commands: F64) -> F64:
        """True elongations (N, n) of ``commands`` under ``x``."""
        return commands * self.gains(x) + self.offsets(x)

    def pose_jacobian(self, x: F64, commands: F64) -> tuple[F64, F64]:
        """Poses (N, 4, 4) at ``commands`` and their Jacobian (N, 6, size) w.r.t. ``x``:
        rows [v; w] as the core's Jacobian (see the module docstring)."""
        arm = self.arm(x)
        q = self.elongations(x, commands)
        poses = arm.forward_batch(q)
        jq = arm.jacobian_batch(q)  # (N, 6, n)
        n_s, n = self.n_sections, self.n_actuators
        out = np.zeros((len(q), 6, self.size))
        sb = self.offset_scales()
        for i, s in enumerate(self.nominal.sections):
            sl = slice(3 * i, 3 * i + 3)
            ji = jq[:, :, sl]  # (N, 6, 3)
            li = q[:, sl]
            dev = li - li.mean(axis=1, keepdims=True)
            r = arm.sections[i].radius
            # radius: d/dx = J_i (-(l - mean l) / r) * dr/dx, dr/dx = r0
            out[:, :, 4 * i] = np.einsum("nkj,nj->nk", ji, -dev * (s.radius / r))
            # rest length: d/dx = J_i [1, 1, 1] * L0
            out[:, :, 4 * i + 1] = ji.sum(axis=2) * s.rest_length
        # offsets and twists act at the base frame of the next section (or the EE).
        frames = np.stack([arm.frames(qk) for qk in q])  # (N, n_s + 1, 4, 4)
        p_ee = poses[:, :3, 3]
        for i in range(n_s):
            z = frames[:, i + 1, :3, 2]
            o = frames[:, i + 1, :3, 3]
            out[:, :3, 4 * i + 2] = z * sb[i]
            out[:, :3, 4 * i + 3] = np.cross(z, p_ee - o)
            out[:, 3:, 4 * i + 3] = z
        # gains: d/dg_m = J[:, m] c_m
        out[:, :, 4 * n_s : 4 * n_s + n] = jq * commands[:, None, :]
        if self.bias:  # offsets: d/db = J_i basis * scale
            for i in range(n_s):
                ji = jq[:, :, 3 * i : 3 * i + 3]
                for a in range(2):
                    out[:, :, 4 * n_s + n + 2 * i + a] = ji @ (BIAS_SCALE * _BIAS_BASIS[a])
        return poses, out
