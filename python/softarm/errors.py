"""The softarm exception hierarchy.

Every error softarm raises derives from :class:`SoftarmError`. Errors caused by bad
input also derive from :class:`ValueError`, so ``except ValueError`` keeps working for
callers that do not know softarm. The native module (``softarm._core``) raises these
same classes: they are defined here once and imported by the Rust bindings.

A message always names the offending argument and, where it helps, its value.
"""

from __future__ import annotations

__all__ = [
    "CapabilityError",
    "ConfigError",
    "DivergenceError",
    "HardwareError",
    "HardwareUnavailableError",
    "InputError",
    "MissingDependencyError",
    "NonFiniteError",
    "OutOfRangeError",
    "OutputError",
    "ParameterError",
    "PoseError",
    "SafetyError",
    "ShapeError",
    "SoftarmError",
    "UnreachableError",
    "VisionError",
]


class SoftarmError(Exception):
    """Base class of every error raised by softarm."""


class InputError(SoftarmError, ValueError):
    """An argument has a wrong shape, type or value.

    ``argument`` names it, ``value`` is the rejected value (None where there is no single
    one) and ``expected`` says what is accepted. Errors from the native core always set
    them; None where a Python caller did not.
    """

    argument: str | None = None
    value: object = None
    expected: str | None = None


class ShapeError(InputError):
    """An array argument has the wrong shape or length."""


class NonFiniteError(InputError):
    """An argument contains NaN or an infinite value (``index``: the first one's flat
    index)."""

    index: int | None = None


class OutOfRangeError(InputError):
    """A value lies outside its allowed range (section index, fraction s, limits);
    ``bounds`` is the closed range ``(min, max)``."""

    bounds: tuple[float, float] | None = None


class ParameterError(InputError):
    """A model parameter is invalid (non-positive length or radius, lower >= upper, ...)."""


class PoseError(InputError):
    """A 4x4 pose is malformed: non-finite, last row not [0, 0, 0, 1], or a rotation
    block that is not orthonormal with determinant +1."""


class DivergenceError(SoftarmError, FloatingPointError):
    """A simulation diverged: its state is no longer finite (time step too large?)."""


class UnreachableError(SoftarmError):
    """A target lies outside what the arm can reach."""


class VisionError(SoftarmError):
    """An image or camera model cannot be used (empty frame, wrong dtype, bad calibration)."""


class HardwareError(SoftarmError):
    """A hardware device failed or reported a fault."""


class HardwareUnavailableError(HardwareError):
    """A device, its driver or its port is absent."""


class SafetyError(HardwareError):
    """A command was refused or the system was stopped by the safety layer."""


class CapabilityError(InputError):
    """An object handed to softarm lacks a method its role needs (a controller without
    plan following or the model's pose); raised when the object is wired in."""


class ConfigError(SoftarmError, ValueError):
    """A configuration file is missing, malformed or inconsistent."""


class OutputError(SoftarmError, OSError):
    """An output file cannot be written (missing folder, full disk, file-size limit); the
    previous file of that name, if any, is left as it was."""


class MissingDependencyError(SoftarmError, ImportError):
    """Something optional that this use needs is not installed. ``extra`` names the
    softarm extra that provides it (``pip install 'softarm[EXTRA]'``), as the one-line
    message does. Raised where the dependency is first needed, never at import."""

    def __init__(self, message: str, extra: str) -> None:
        super().__init__(message)
        self.extra = extra

    def __reduce__(self) -> tuple[type[MissingDependencyError], tuple[str, str]]:
        # Pickled (Ray, multiprocessing) with its extra: the default would call cls(message).
        return (type(self), (str(self.args[0]) if self.args else "", self.extra))
