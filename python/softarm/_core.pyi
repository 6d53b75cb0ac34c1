"""Type stubs for the native module ``softarm._core`` (kept honest by mypy.stubtest)."""

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
