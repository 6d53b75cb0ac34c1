"""Type stubs for the native module ``softarm._core`` (kept honest by mypy.stubtest)."""

from collections.abc import Sequence
from typing import final

import numpy as np
import numpy.typing as npt

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
        """End-effector pose (4, 4) in the base frame (eq. 3)."""
    def jacobian(self, q: _ArrayLike) -> _F64:
        """Analytic Jacobian (6, n), rows [vx, vy, vz, wx, wy, wz] (eq. 4-6)."""
    def forward_jacobian(self, q: _ArrayLike) -> tuple[_F64, _F64]:
        """Pose (4, 4) and Jacobian (6, n) from one pass."""
    def point(self, q: _ArrayLike, section: int, s: float) -> tuple[_F64, _F64]:
        """Backbone point (3,) at fraction s of a section, and its Jacobian (3, n)."""
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
    """A pneumatic continuum arm in actuator space; q = actuator elongations (m)."""

    def __new__(cls, sections: list[Section]) -> SoftArm: ...
    @staticmethod
    def blackberry() -> SoftArm: ...
    @property
    def n_actuators(self) -> int: ...
    @property
    def sections(self) -> list[Section]: ...
    def configuration(self, q: _ArrayLike) -> _F64:
        """Eq. (1) per section: (arc length, bending angle, bending direction)."""

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
        """Point (3,) at a scalar u, or points (N, 3) at an array of u."""
    def sample(self, n: int) -> _F64:
        """n points evenly spaced in u, (n, 3)."""

@final
class Segment:
    """A line segment from a to b; u is the fraction from a to b."""

    def __new__(cls, a: _ArrayLike, b: _ArrayLike) -> Segment: ...
    @property
    def a(self) -> _F64: ...
    @property
    def b(self) -> _F64: ...

@final
class PointCloud:
    """An (N, 3) point cloud with a bounding-volume hierarchy (parry3d)."""

    def __new__(cls, points: _ArrayLike) -> PointCloud: ...
    @property
    def points(self) -> _F64: ...
    def __len__(self) -> int: ...

@final
class TriangleMesh:
    """A triangle mesh (parry3d); arcs meet it as chords within `tolerance` (m)."""

    def __new__(
        cls, vertices: _ArrayLike, triangles: _ArrayLike, tolerance: float = 1e-4
    ) -> TriangleMesh: ...
    @property
    def tolerance(self) -> float: ...

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
        """"reached", "stalled" or "iteration_limit"."""

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

def path_clearance(
    arm: SoftArm | ArcChain,
    path: _ArrayLike,
    obstacles: Sequence[_Obstacle],
    substeps: int = 1,
) -> float:
    """Exact clearance along a path, with substeps - 1 interpolated configurations."""

def paper_scenario(name: str) -> tuple[_F64, list[PolynomialCurve]]:
    """The planning paper's simulation "line", "curve" or "tree": (goal, curves)."""
