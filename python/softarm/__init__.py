"""softarm: model, control, plan and see a pneumatic soft harvesting arm.

The kinematic math lives in the Rust core (``softarm._core``); this package re-exports it
and adds vision, hardware drivers, simulation, the harvest state machine and the CLI.

>>> import softarm
>>> arm = softarm.SoftArm.blackberry()
>>> arm.forward([0.0] * 9)[2, 3]  # straight arm: 3 x 0.15 m + 2 x 12 mm plates + 60 mm gripper
np.float64(0.534)
"""

import importlib
import importlib.metadata
import pkgutil
from typing import Any

from softarm import _core
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
    "Calibration",
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
    "calibrate",
    "closest",
    "simulate_harvest",
]

try:
    #: The installed distribution's version (pyproject.toml), as ``softarm --version``.
    __version__: str = importlib.metadata.version("softarm")
except importlib.metadata.PackageNotFoundError:  # run from a source tree, not installed
    __version__ = _core.__version__

#: Public subpackages and modules, imported on first attribute access: vision pulls in
#: OpenCV, and the kinematics should not pay for that.
_LAZY_SUBPACKAGES = frozenset(
    m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")
)


def _attach_python_side() -> None:
    """Docstrings from the stub (see :mod:`softarm._stubdocs`) and the Python-side
    constructors of the native classes."""
    from softarm._arm_config import from_config
    from softarm._stubdocs import apply_stub_docstrings

    apply_stub_docstrings(_core)
    setattr(SoftArm, "from_config", classmethod(from_config))  # noqa: B010  (native class)


_attach_python_side()


#: Functions and classes re-exported lazily, name -> (module, its name there): their
#: subpackages import scipy.optimize, OpenCV and the simulator.
_LAZY_NAMES = {
    "calibrate": ("softarm.calibration", "calibrate"),
    "Calibration": ("softarm.calibration", "Calibration"),
    # The simulated harvest, softarm.harvest.simulate: a report from one call.
    "simulate_harvest": ("softarm.harvest.rigs.sim.simulate", "simulate"),
}


def __getattr__(name: str) -> Any:
    if name in _LAZY_NAMES:
        module, attr = _LAZY_NAMES[name]
        return getattr(importlib.import_module(module), attr)
    if name in _LAZY_SUBPACKAGES:
        return importlib.import_module(f"softarm.{name}")
    raise AttributeError(f"module 'softarm' has no attribute {name!r}")


#: Modules that serve the command line and the package itself, not a user of the API:
#: importable, left out of ``dir(softarm)``.
_INTERNAL = frozenset({"checks", "cli", "commands", "files"})


def __dir__() -> list[str]:
    # The lazily imported subpackages are part of the API: list them beside the names.
    return sorted({*__all__, *(_LAZY_SUBPACKAGES - _INTERNAL)})
