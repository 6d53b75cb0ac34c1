"""softarm: model, control, plan and see a pneumatic soft harvesting arm.

The kinematic math lives in the Rust core (``softarm._core``); this package re-exports it
and adds vision, hardware drivers, simulation, the harvest state machine and the CLI.

>>> import softarm
>>> arm = softarm.SoftArm.blackberry()
>>> arm.forward([0.0] * 9)[2, 3]  # straight arm: 3 x 0.15 m + 2 x 12 mm plates + 60 mm gripper
np.float64(0.534)
"""

from softarm._core import (
    ArcChain,
    Gains,
    Resolver,
    Section,
    SoftArm,
    Solution,
    StepResult,
    __version__,
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
    "ConfigError",
    "Gains",
    "HardwareError",
    "HardwareUnavailableError",
    "InputError",
    "NonFiniteError",
    "OutOfRangeError",
    "ParameterError",
    "PoseError",
    "Resolver",
    "SafetyError",
    "Section",
    "ShapeError",
    "SoftArm",
    "SoftarmError",
    "Solution",
    "StepResult",
    "UnreachableError",
    "VisionError",
    "__version__",
]
