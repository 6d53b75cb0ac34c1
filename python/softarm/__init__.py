"""softarm: model, control, plan and see a pneumatic soft harvesting arm.

The kinematic math lives in the Rust core (``softarm._core``); this package re-exports it
and adds vision, hardware drivers, simulation, the harvest state machine and the CLI.

>>> import softarm
>>> arm = softarm.SoftArm.blackberry()
>>> arm.forward([0.0] * 9)[2, 3]  # straight arm: 3 x 0.15 m + 2 x 12 mm plates + 60 mm gripper
np.float64(0.534)
"""

import importlib
from types import ModuleType

from softarm._core import (
    ArcChain,
    Closest,
    Gains,
    LagModel,
    Plan,
    PointCloud,
    PolynomialCurve,
    PotentialFieldPlanner,
    Resolver,
    Section,
    Segment,
    SoftArm,
    Solution,
    StepResult,
    TriangleMesh,
    __version__,
    closest,
)
from softarm.errors import (
    ConfigError,
    HardwareError,
    HardwareUnavailableError,
    InputError,
    NonFiniteError,
    OutOfRangeError,
    ParameterError,
    PoseError,
    SafetyError,
    ShapeError,
    SoftarmError,
    UnreachableError,
    VisionError,
)

__all__ = [
    "ArcChain",
    "Closest",
    "ConfigError",
    "Gains",
    "HardwareError",
    "HardwareUnavailableError",
    "InputError",
    "LagModel",
    "NonFiniteError",
    "OutOfRangeError",
    "ParameterError",
    "Plan",
    "PointCloud",
    "PolynomialCurve",
    "PoseError",
    "PotentialFieldPlanner",
    "Resolver",
    "SafetyError",
    "Section",
    "Segment",
    "ShapeError",
    "SoftArm",
    "SoftarmError",
    "Solution",
    "StepResult",
    "TriangleMesh",
    "UnreachableError",
    "VisionError",
    "__version__",
    "closest",
]

#: Subpackages imported on first attribute access: vision pulls in OpenCV, and the
#: kinematics should not pay for that.
_LAZY_SUBPACKAGES = frozenset({"vision", "sim", "hardware", "harvest", "config", "planning"})


def __getattr__(name: str) -> ModuleType:
    if name in _LAZY_SUBPACKAGES:
        return importlib.import_module(f"softarm.{name}")
    raise AttributeError(f"module 'softarm' has no attribute {name!r}")
