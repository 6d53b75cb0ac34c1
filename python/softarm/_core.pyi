"""Type stubs for the native module ``softarm._core`` (kept honest by mypy.stubtest)."""

from collections.abc import Sequence
from pathlib import Path
from typing import final

import numpy as np
import numpy.typing as npt

from softarm.config import ArmConfig, Config

__version__: str

_F64 = npt.NDArray[np.float64]
_ArrayLike = npt.ArrayLike

@final
class Section:
    """Geometry and limits of one pneumatic section (SI units)."""

    def __new__(
        cls,
        radius: float,
        rest_length: float,
        lower: float,
        upper: float,
        offset: float = 0.0,
        twist: float = 0.0,
    ) -> Section: ...
    @property
    def radius(self) -> float: ...
    @property
    def rest_length(self) -> float: ...
    @property
    def lower(self) -> float: ...
    @property
    def upper(self) -> float: ...
    @property
    def offset(self) -> float: ...
    @property
    def twist(self) -> float: ...
    def __reduce__(
        self,
    ) -> tuple[type[Section], tuple[float, float, float, float, float, float]]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __ne__(self, value: object, /) -> bool: ...
    __hash__: None  # type: ignore[assignment]

class _Kinematics:
    @property
    def n_sections(self) -> int: ...
    @property
    def n_dofs(self) -> int: ...
    @property
    def lower(self) -> _F64: ...
    @property
    def upper(self) -> _F64: ...
    def forward(self, q: _ArrayLike) -> _F64:
        """End-effector pose (4, 4) in the base frame (eq. 3).

        ``q`` outside the limits ``lower``/``upper`` is still computed (the model
        extrapolates; a resolver never commands it) as long as every section keeps a
        positive arc length. A ``q`` that gives a section a non-positive arc length (for
        the blackberry arm, ``[-0.2] * 9``) has no geometry: it raises
        :class:`softarm.errors.ParameterError` with ``argument`` ``"q[3i..3i+3]"`` (the
        section's elongations), ``value`` the arc length and ``expected`` the reason. The
        same holds for every kinematic call (``jacobian``, ``point``, ``frames``,
        ``backbone``, ``configuration``; a batch names ``"qs[row, 3i..3i+3]"``)."""
    def jacobian(self, q: _ArrayLike) -> _F64:
        """Analytic Jacobian (6, n), rows [vx, vy, vz, wx, wy, wz] (eq. 4-6)."""
    def forward_jacobian(self, q: _ArrayLike) -> tuple[_F64, _F64]:
        """Pose (4, 4) and Jacobian (6, n) from one pass."""
    def point(self, q: _ArrayLike, section: int, s: float) -> tuple[_F64, _F64]:
        """Backbone point (3,) at fraction s of ``section`` (counted from 0: 0 = proximal),
        and its Jacobian (3, n)."""
    def frames(self, q: _ArrayLike) -> _F64:
        """Base frame of every section, then the end effector: (n_sections + 1, 4, 4)."""
    def backbone(self, q: _ArrayLike, samples: int = 20) -> _F64:
        """(n_sections * samples, 3) points along the arcs, ends included."""
    def forward_batch(self, qs: _ArrayLike) -> _F64:
        """(N, n) configurations -> (N, 4, 4) poses; releases the GIL."""
    def jacobian_batch(self, qs: _ArrayLike) -> _F64:
        """(N, n) configurations -> (N, 6, n) Jacobians; releases the GIL."""

@final
class SoftArm(_Kinematics):
    """A pneumatic continuum arm in actuator space; q = actuator elongations (m).

    A ``q`` outside the limits ``lower``/``upper`` is still computed by every kinematic
    call (the model extrapolates) as long as each section keeps a positive arc length; one
    that gives a section a non-positive arc length (``[-0.2] * 9`` for the blackberry arm)
    has no geometry and raises ``ParameterError`` naming ``q[3i..3i+3]``. ``repr`` shows
    the sections; two arms with equal sections compare equal (a pickled copy does)."""

    def __new__(cls, sections: list[Section]) -> SoftArm: ...
    @staticmethod
    def blackberry() -> SoftArm: ...
    @classmethod
    def from_config(cls, config: str | Path | Config | ArmConfig) -> SoftArm:
        """The arm of a TOML configuration's ``[arm]`` section (a path, a loaded Config
        or its ArmConfig); defined in Python (``softarm._arm_config``)."""
    @property
    def n_actuators(self) -> int: ...
    @property
    def sections(self) -> list[Section]: ...
    def configuration(self, q: _ArrayLike) -> _F64:
        """Eq. (1) per section: (arc length, bending angle, bending direction)."""
    def __reduce__(self) -> tuple[type[SoftArm], tuple[list[Section]]]: ...
    def __eq__(self, value: object, /) -> bool:
        """Equal when every section is (a pickled or deep copy compares equal)."""
    def __hash__(self) -> int: ...

@final
class ArcChain(_Kinematics):
    """A chain of arcs in configuration space, q_i = [L_i, Theta_i, phi_i]."""

    def __new__(
        cls,
        lengths: _ArrayLike,
        lower: _ArrayLike | None = None,
        upper: _ArrayLike | None = None,
    ) -> ArcChain: ...
    @property
    def lengths(self) -> _F64: ...
    def straight(self) -> _F64: ...
    def __reduce__(self) -> tuple[type[ArcChain], tuple[_F64, _F64, _F64]]: ...

@final
class Gains:
    """Tuning parameters of :class:`Resolver` (redundancy paper eq. 7, 13, 20, 23-25).

    Keyword-only constructor; every field defaults to the blackberry preset
    (``Gains.default_for(SoftArm.blackberry())``). Units: every ``*_alpha`` and the task weights
    ``hybrid_position`` (gamma_6) and ``hybrid_orientation`` (gamma_4) are dimensionless
    fractions per step. The joint-limit weights ``position_gamma`` (gamma_2),
    ``orientation_gamma`` (gamma_3) and ``hybrid_gamma`` (gamma_5) multiply grad H, which is
    in 1/m, so they are in m^2 and must be <= 0 (descend H). Switch distances are in m
    (position, hybrid) or rad (orientation). ``schedule`` is "step" (eq. 23-25) or
    "smooth" (gamma * e^2 / (e^2 + d^2), the default). ``axis_mask`` selects the controlled
    orientation axes (x, y, z) of the base frame; the paper controls x and z.
    ``max_step`` (m) caps the task part of one increment (the joint-limit part at half).
    ``lag_periods`` is the actuator lag (first-order time constant, sensor filter included,
    in control periods) a closed-loop step must tolerate: with a measured pose and no
    ``plant_q``, the largest task gain (alpha, or hybrid_alpha * max(hybrid_position,
    hybrid_orientation)) is capped at tanh(1 / (4 lag_periods)) (docs/control.md);
    default 20. ``loop_damping`` and ``loop_singular_threshold`` replace ``damping`` and
    ``singular_threshold`` in a step given a measured pose (closed loop, with or without
    ``plant_q``): larger, because the plant is not the model along the ill-conditioned
    directions of the damped pseudo-inverses (docs/control.md). ``repulsion_gain`` (k_r),
    ``influence_distance`` (rho_0, m) and ``obstacle_radius`` (m, a cane's by default) set
    the obstacle repulsion of planning paper eq. (9): the surface gap g of the resolver's
    ``Body`` (piece by piece, the backbone distance less the piece's radius and
    ``obstacle_radius``) is asked to grow by k_r (1/g - 1/rho_0) / g^2 m per step
    (docs/control.md, section 4). Every field is bounded (see ``Gains.validate``
    in the Rust docs).
    """

    def __new__(
        cls,
        *,
        conventional_alpha: float = ...,
        position_alpha: float = ...,
        position_gamma: float = ...,
        position_switch: float = ...,
        orientation_alpha: float = ...,
        orientation_gamma: float = ...,
        orientation_switch: float = ...,
        hybrid_alpha: float = ...,
        hybrid_position: float = ...,
        hybrid_orientation: float = ...,
        hybrid_gamma: float = ...,
        hybrid_switch: float = ...,
        schedule: str = ...,
        axis_mask: tuple[bool, bool, bool] | list[bool] = ...,
        damping: float = ...,
        singular_threshold: float = ...,
        loop_damping: float = ...,
        loop_singular_threshold: float = ...,
        limit_margin: float = ...,
        max_step: float = ...,
        lag_periods: float = ...,
        repulsion_gain: float = ...,
        influence_distance: float = ...,
        obstacle_radius: float = ...,
    ) -> Gains: ...
    @staticmethod
    def for_lag(tau_s: float, period_s: float) -> Gains:
        """The defaults with ``lag_periods = tau_s / period_s`` (tau_s in [0, 100] s, the
        actuators' and the sensor filter's time constants summed)."""
    @classmethod
    def from_dict(cls, d: dict[str, object]) -> Gains:
        """Gains from fields as ``as_dict`` returns them; missing ones keep the defaults."""
    def __reduce__(self) -> tuple[object, tuple[dict[str, object]]]: ...
    @staticmethod
    def paper() -> Gains:
        """The paper's printed gains, eq. (23)-(25), read in the units above."""
    def replace(self, **changes: object) -> Gains:
        """A copy with some fields changed (same keywords as the constructor)."""
    def as_dict(self) -> dict[str, object]: ...
    @property
    def conventional_alpha(self) -> float: ...
    @property
    def position_alpha(self) -> float: ...
    @property
    def position_gamma(self) -> float: ...
    @property
    def position_switch(self) -> float: ...
    @property
    def orientation_alpha(self) -> float: ...
    @property
    def orientation_gamma(self) -> float: ...
    @property
    def orientation_switch(self) -> float: ...
    @property
    def hybrid_alpha(self) -> float: ...
    @property
    def hybrid_position(self) -> float: ...
    @property
    def hybrid_orientation(self) -> float: ...
    @property
    def hybrid_gamma(self) -> float: ...
    @property
    def hybrid_switch(self) -> float: ...
    @property
    def schedule(self) -> str: ...
    @property
    def axis_mask(self) -> tuple[bool, bool, bool]: ...
    @property
    def damping(self) -> float: ...
    @property
    def singular_threshold(self) -> float: ...
    @property
    def loop_damping(self) -> float: ...
    @property
    def loop_singular_threshold(self) -> float: ...
    @property
    def limit_margin(self) -> float: ...
    @property
    def max_step(self) -> float: ...
    @property
    def lag_periods(self) -> float: ...
    @property
    def repulsion_gain(self) -> float: ...
    @property
    def influence_distance(self) -> float: ...
    @property
    def obstacle_radius(self) -> float: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __ne__(self, value: object, /) -> bool: ...
    __hash__: None  # type: ignore[assignment]

@final
class StepResult:
    """What ``Resolver.step`` returns: the next command and what happened.

    A small object rather than a bare array so that saturation and the errors at the
    input state come with the command; ``unclamped`` is what an unconstrained controller
    would send (used to count infeasible commands).
    """

    @property
    def q(self) -> _F64:
        """The next command (n,), always inside [lower, upper]."""
    @property
    def unclamped(self) -> _F64:
        """q + dq before any clamping (n,)."""
    @property
    def saturated(self) -> bool:
        """True when a coordinate had to be held at a limit."""
    @property
    def position_error(self) -> float:
        """||e_p|| (m) at the input state."""
    @property
    def orientation_error(self) -> float:
        """Masked ||e_zeta|| (rad) at the input state; 0 for a point target."""
    @property
    def clearance(self) -> float:
        """Smallest surface gap (m) of the model arm at q to the obstacles within the
        influence distance; inf when none is."""
    def __reduce__(self) -> tuple[object, tuple[_F64, _F64, bool, float, float, float]]: ...

def _rebuild_step_result(
    q: _ArrayLike,
    unclamped: _ArrayLike,
    saturated: bool,
    position_error: float,
    orientation_error: float,
    clearance: float,
) -> StepResult:
    """Unpickler of ``StepResult``."""

@final
class Solution:
    """What ``Resolver.solve`` returns (read-only)."""

    @property
    def q(self) -> _F64:
        """The best configuration found (n,), inside the limits."""
    @property
    def converged(self) -> bool: ...
    @property
    def steps(self) -> int:
        """Steps run: the last configuration evaluated is q0 after ``steps`` steps (at
        most ``max_steps``)."""
    @property
    def best_step(self) -> int:
        """The step at which ``q`` was reached (q0 after ``best_step`` steps, at most
        ``steps``)."""
    @property
    def position_error(self) -> float:
        """||e_p|| at q (m)."""
    @property
    def orientation_error(self) -> float:
        """Masked ||e_zeta|| at q (rad)."""
    @property
    def termination(self) -> str:
        """Why the iteration stopped: "converged", "stuck" (a step left q unchanged, e.g.
        the straight rest pose in position mode) or "step_limit"."""
    def __reduce__(self) -> tuple[object, tuple[_F64, bool, int, float, float, str, int]]: ...

def _rebuild_solution(
    q: _ArrayLike,
    converged: bool,
    steps: int,
    position_error: float,
    orientation_error: float,
    termination: str,
    best_step: int | None = None,
) -> Solution:
    """Unpickler of ``Solution``."""

@final
class Resolver:
    """Gain-scheduled task-priority resolver for a :class:`SoftArm`.

    ``mode``: "conventional" (eq. 7; full Jacobian for a pose target, position Jacobian
    for a point), "position" / "orientation" (eq. 13, over joint-limit avoidance) or
    "hybrid" (eq. 20). ``gains=None`` uses ``Gains()``. ``body`` is the :class:`Body` the
    obstacle repulsion keeps off the obstacles, piece by piece (None: ``Body.for_arm(arm,
    0.0)``, the gripper ending at the end-effector frame); a body with another number of
    sections than ``arm`` is a ``ShapeError`` naming ``body``, anything but a ``Body`` an
    ``InputError`` naming it.
    """

    def __new__(
        cls,
        arm: SoftArm,
        mode: str | None = None,
        gains: Gains | None = None,
        body: Body | None = None,
    ) -> Resolver:
        """``mode`` None means "hybrid"; ``gains`` None means ``Gains()``; ``body`` None
        means ``Body.for_arm(arm, 0.0)``."""
    def __reduce__(self) -> tuple[type[Resolver], tuple[SoftArm, str, Gains, Body]]: ...
    @property
    def mode(self) -> str: ...
    @property
    def gains(self) -> Gains: ...
    @property
    def arm(self) -> SoftArm: ...
    @property
    def body(self) -> Body:
        """The body the obstacle repulsion measures."""
    def step(
        self,
        q: _ArrayLike,
        target: _ArrayLike,
        current: _ArrayLike | None = None,
        *,
        obstacles: object | None = None,
        plant_q: _ArrayLike | None = None,
    ) -> StepResult:
        """One step from ``q`` towards ``target`` ((4, 4) pose, or (3,) point in
        "position"/"conventional" mode); ``current`` is the measured pose (closed loop,
        alpha capped by ``gains.lag_periods``) or None (the model's forward kinematics).
        ``obstacles``: what ``closest`` takes (curves, segments, clouds, meshes, points), one
        or a sequence; each repels the arm's body (arcs, plates, gripper) by eq. (9) in the
        null space of every task. ``plant_q``: a :class:`LagModel`'s prediction of the
        elongations reached; the measured error is then corrected by the motion still in
        flight and alpha is not capped."""
    def solve(
        self,
        q0: _ArrayLike,
        target: _ArrayLike,
        max_steps: int | None = 1000,
        position_tolerance: float | None = 0.0001,
        orientation_tolerance: float | None = 0.0017453292519943296,
        *,
        obstacles: object | None = None,
    ) -> Solution:
        """Steps on the model from ``q0`` until the controlled errors are within tolerance
        (``position_tolerance`` in m, default 0.1 mm; ``orientation_tolerance`` in rad,
        default 0.1 deg; None also means the default) or ``max_steps`` steps have run;
        an unreachable target returns ``converged=False`` with the best error.
        ``Solution.steps`` is the number of steps run, ``Solution.best_step`` the one
        that reached ``q``. Releases the GIL."""

@final
class LagModel:
    """First-order lag of the actuators, y <- y + (1 - exp(-T/tau)) (u - y): the predictor
    (``plant_q``) of the lag-aware closed loop (docs/control.md)."""

    def __new__(cls, tau_s: float, period_s: float, q0: _ArrayLike) -> LagModel: ...
    @property
    def q(self) -> _F64:
        """Predicted elongations now (n,)."""
    def advance(self, command: _ArrayLike) -> _F64:
        """One period with ``command`` held; the predicted elongations after it."""
    def reset(self, q: _ArrayLike) -> None:
        """Settles the model at ``q``."""
    def __reduce__(self) -> tuple[type[LagModel], tuple[float, float, _F64]]:
        """Pickles as ``LagModel(tau_s, period_s, q)``: the predicted state travels."""

LEAD_GAIN_CAP: float
PREDICTED_ALPHA_MAX: float
PREDICTED_ALPHA_LAG_S: float
PREDICTED_ALPHA_MIN: float

def play(output: _ArrayLike, input: _ArrayLike, width: _ArrayLike) -> _F64:
    """The play (backlash) operator per channel, ``clip(output, input - width/2, input +
    width/2)`` (a new array): the one law of play, which the simulated hysteresis and the
    controller's measurement model both apply. Raises ShapeError for lengths that differ,
    NonFiniteError for a non-finite output or input, ParameterError for a width < 0."""

def lead_gain(tau_s: float, period_s: float, cap: float = ...) -> float:
    """The regulators' pre-compensation gain ``k``: half the overshoot-free bound
    ``a/(1 - a)``, ``a = exp(-period_s/tau_s)``, at most ``cap`` (``LEAD_GAIN_CAP``,
    1.5); 0 for ``tau_s = 0`` (docs/control.md, section 6)."""

def predicted_loop_alpha(lag_s: float) -> float:
    """The resolver's gain for the loop closed through the lag model, for a measurement
    chain lagging ``lag_s`` (s) in all: ``PREDICTED_ALPHA_LAG_S / lag_s`` within
    [``PREDICTED_ALPHA_MIN`` (the default ``hybrid_alpha``), ``PREDICTED_ALPHA_MAX``];
    the largest for no lag (docs/control.md, section 6)."""

# --- distance queries and planning (planning paper eq. 9-18) -------------------------

@final
class PolynomialCurve:
    """A polynomial space curve F(u) = sum_k c_k u^k over [u_min, u_max] (eq. 10)."""

    def __new__(cls, coeffs: _ArrayLike, u_range: tuple[float, float]) -> PolynomialCurve: ...
    @property
    def coeffs(self) -> _F64:
        """(3, d + 1) coefficients, ascending powers; row 0 is x(u)."""
    @property
    def u_range(self) -> tuple[float, float]: ...
    @property
    def degree(self) -> int: ...
    def __call__(self, u: float | _ArrayLike) -> _F64:
        """Point (3,) at a scalar u, or points (N, 3) at an array of u, inside u_range."""
    def sample(self, n: int) -> _F64:
        """n points evenly spaced in u, (n, 3)."""
    def __reduce__(
        self,
    ) -> tuple[type[PolynomialCurve], tuple[_F64, tuple[float, float]]]: ...

@final
class Segment:
    """A line segment from a to b; u is the fraction from a to b."""

    def __new__(cls, a: _ArrayLike, b: _ArrayLike) -> Segment: ...
    @property
    def a(self) -> _F64: ...
    @property
    def b(self) -> _F64: ...
    def __reduce__(self) -> tuple[type[Segment], tuple[_F64, _F64]]: ...

@final
class PointCloud:
    """An (N, 3) point cloud with a bounding-volume hierarchy (parry3d)."""

    def __new__(cls, points: _ArrayLike) -> PointCloud: ...
    @property
    def points(self) -> _F64: ...
    def __len__(self) -> int: ...
    def __reduce__(self) -> tuple[type[PointCloud], tuple[_F64]]: ...

@final
class TriangleMesh:
    """A triangle mesh (parry3d); arcs meet it as chords within `tolerance` (m)."""

    def __new__(
        cls, vertices: _ArrayLike, triangles: _ArrayLike, tolerance: float = 1e-4
    ) -> TriangleMesh: ...
    @property
    def tolerance(self) -> float: ...
    @property
    def vertices(self) -> _F64:
        """(N, 3) vertices."""
    @property
    def triangles(self) -> npt.NDArray[np.int64]:
        """(M, 3) vertex indices of the triangles."""
    def __reduce__(
        self,
    ) -> tuple[type[TriangleMesh], tuple[_F64, npt.NDArray[np.int64], float]]: ...

_Obstacle = PolynomialCurve | Segment | PointCloud | TriangleMesh | _ArrayLike

@final
class Closest:
    """The closest pair between an arm and an obstacle."""

    @property
    def distance(self) -> float: ...
    @property
    def section(self) -> int: ...
    @property
    def s(self) -> float: ...
    @property
    def u(self) -> float: ...
    @property
    def arm_point(self) -> _F64: ...
    @property
    def obstacle_point(self) -> _F64: ...
    def __reduce__(self) -> tuple[object, tuple[float, int, float, float, _F64, _F64]]: ...

def _rebuild_closest(
    distance: float,
    section: int,
    s: float,
    u: float,
    arm_point: _ArrayLike,
    obstacle_point: _ArrayLike,
) -> Closest:
    """Unpickler of ``Closest``."""

def closest(arm: SoftArm | ArcChain, q: _ArrayLike, obstacle: _Obstacle) -> Closest:
    """Closest pair between the arm at q and the obstacle (eq. 12-18, global)."""

@final
class Plan:
    """A planned path (planning paper eq. 9)."""

    @property
    def path(self) -> _F64:
        """(iterations + 1, n) configurations, q0 first."""
    @property
    def tip_path(self) -> _F64:
        """(iterations + 1, 3) tip positions."""
    @property
    def reached(self) -> bool: ...
    @property
    def iterations(self) -> int: ...
    @property
    def min_clearance(self) -> float:
        """Smallest exact distance of the whole backbone to any obstacle (m)."""
    @property
    def termination(self) -> str:
        """ "reached", "stalled", "iteration_limit" or "non_finite_step"."""
    def __reduce__(self) -> tuple[object, tuple[_F64, _F64, int, float, str]]: ...

def _rebuild_plan(
    path: _ArrayLike, tip_path: _ArrayLike, iterations: int, min_clearance: float, termination: str
) -> Plan:
    """Unpickler of ``Plan``."""

@final
class PotentialFieldPlanner:
    """Potential-field planner (eq. 9) on a SoftArm or an ArcChain."""

    def __new__(
        cls,
        arm: SoftArm | ArcChain,
        *,
        attraction_gain: float = 1.0,
        max_tip_step: float = 0.15,
        repulsion_gain: float = 3e-5,
        influence_distance: float = 0.1,
        max_step_fraction: float = 0.04,
        damping: float = 0.05,
        goal_tolerance: float = 0.01,
        max_iterations: int = 500,
        stall_window: int = 20,
        stall_tolerance: float = 1e-3,
        arm_samples: int | None = None,
    ) -> PotentialFieldPlanner: ...
    @property
    def options(self) -> dict[str, float | int | None]: ...
    def plan(
        self, q0: _ArrayLike, goal: _ArrayLike, obstacles: Sequence[_Obstacle] | None = None
    ) -> Plan:
        """Plan from q0 to the tip position goal; releases the GIL."""
    def __reduce__(self) -> tuple[object, tuple[SoftArm | ArcChain]]: ...

def path_clearance(
    arm: SoftArm | ArcChain,
    path: _ArrayLike,
    obstacles: Sequence[_Obstacle],
    substeps: int = 1,
) -> float:
    """Exact clearance along a path, with substeps - 1 interpolated configurations."""

def paper_scenario(name: str) -> tuple[_F64, list[PolynomialCurve]]:
    """The planning paper's simulation "line", "curve" or "tree": (goal, curves)."""

# --- the arm's body -------------------------------------------------------------------

ACTUATOR_RADIUS: float
GRIPPER_RADIUS: float
CANE_RADIUS: float

@final
class Body:
    """The arm's body, the one description every clearance measures: each section's tube
    (``section_radii``: ring radius + ``ACTUATOR_RADIUS``), each inner section's end plate
    (its section's radius), and the gripper, a capsule of ``gripper_radius`` along the
    end-effector's z axis from ``gripper_back`` behind its frame to ``grasp_offset``
    ahead of it (m)."""

    def __new__(
        cls,
        section_radii: _ArrayLike,
        gripper_radius: float,
        gripper_back: float,
        grasp_offset: float,
    ) -> Body: ...
    @staticmethod
    def for_arm(arm: SoftArm, grasp_offset: float) -> Body:
        """The body of ``arm``: its ring radii + ``ACTUATOR_RADIUS``, a gripper of
        ``GRIPPER_RADIUS`` from the distal arc's tip to ``grasp_offset`` (m) ahead of the
        end-effector frame."""
    @property
    def section_radii(self) -> _F64:
        """Each section's surface radius about its backbone (m), proximal first."""
    @property
    def gripper_radius(self) -> float: ...
    @property
    def gripper_back(self) -> float: ...
    @property
    def grasp_offset(self) -> float: ...
    @property
    def widest(self) -> float:
        """The widest surface radius of the body (m)."""
    def gap(
        self,
        arm: SoftArm | ArcChain,
        q: _ArrayLike,
        obstacles: Sequence[_Obstacle],
        obstacle_radius: float = ...,
    ) -> float:
        """Smallest surface gap (m) between the body on ``arm`` at ``q`` and
        ``obstacles``, each of radius ``obstacle_radius`` (``CANE_RADIUS`` by default):
        the exact backbone distance of each piece less its radius and the obstacle's; inf
        without obstacles, below zero when the surfaces overlap."""
    def __reduce__(self) -> tuple[type[Body], tuple[_F64, float, float, float]]: ...
    def __eq__(self, value: object, /) -> bool: ...
    def __ne__(self, value: object, /) -> bool: ...
    __hash__: None  # type: ignore[assignment]
