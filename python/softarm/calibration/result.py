"""The fitted model (:class:`Calibration`) and its TOML file (``model.toml``).

``model.toml`` holds the fitted sections in the same ``[[arm.sections]]`` layout as the
installation config (so its arm can be pasted into ``hw.toml``), the actuator gains and
the residual statistics on the fit data::

    format = 1
    [[arm.sections]]
    radius = 0.0281
    ...
    [actuators]
    gain = [1.02, 0.97, ...]   # true elongation = gain x command
    [fit]
    samples = 80
    position_median_mm = 0.11
    ...
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm._core import SoftArm
from softarm.calibration.metrics import PoseErrorStats
from softarm.calibration.model_file import FORMAT, SECTION_KEYS, model_fields
from softarm.checks import FloatArray as F64
from softarm.errors import NonFiniteError, ShapeError
from softarm.files import load_toml, write_text
from softarm.units import MAX_PSI, METRES_PER_PSI

__all__ = ["Calibration", "GainMap", "load_calibration", "load_model"]


_SECTION_KEYS = tuple(SECTION_KEYS)


@dataclass
class Calibration:
    """A fitted arm model: ``predict(commands) = arm.forward(actuator_gain * commands)``.

    Attributes:
        arm: the fitted geometry (elongation limits scaled by the gains).
        actuator_gain: (n,) true elongation / commanded elongation.
        fit: residual statistics on the fit data (mm, deg).
        parameters: fitted deviations from the nominal arm by name (see ``ParameterMap``).
        parameter_std: their standard deviations from the fit's covariance.
        converged: the solver's success flag, False too when the excitation left
            parameters undetermined; ``message`` its reason.
    """

    arm: SoftArm
    actuator_gain: F64
    fit: PoseErrorStats
    parameters: dict[str, float] = field(default_factory=dict)
    parameter_std: dict[str, float] = field(default_factory=dict)
    converged: bool = True
    message: str = ""
    #: (n,) elongation offsets (m): true elongation = gain x command + offset (zero
    #: unless fitted with ``bias=True``).
    actuator_offset: F64 = field(default_factory=lambda: np.zeros(0))
    #: Indices (into the samples given) of the outlying samples the fit dropped.
    outliers: tuple[int, ...] = ()
    #: Parameters the excitation could not determine (set by the prior alone).
    unidentifiable: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.actuator_offset.size == 0:
            self.actuator_offset = np.zeros(self.arm.n_actuators)

    def _commands(self, commands: npt.ArrayLike) -> F64:
        c = np.asarray(commands, dtype=np.float64)
        n = self.arm.n_actuators
        if c.ndim != 2 or c.shape[1] != n:
            raise ShapeError(f"commands: expected shape (N, {n}), got {c.shape}")
        if not np.all(np.isfinite(c)):
            raise NonFiniteError("commands: contains NaN or inf")
        return c

    def elongations(self, commands: npt.ArrayLike) -> F64:
        """True elongations (N, n) the fitted model expects for ``commands``."""
        return self._commands(commands) * self.actuator_gain + self.actuator_offset

    def commands_for(self, elongations: npt.ArrayLike) -> F64:
        """Commands that give ``elongations`` (m) on the fitted arm: elongation / gain."""
        e = np.asarray(elongations, dtype=np.float64)
        if e.shape[-1:] != (self.arm.n_actuators,) or not np.all(np.isfinite(e)):
            raise ShapeError(f"elongations: expected finite (..., {self.arm.n_actuators})")
        return (e - self.actuator_offset) / self.actuator_gain

    def pressure_map(self, max_psi: float = MAX_PSI) -> GainMap:
        """The elongation <-> psi map of the fitted actuators, for
        ``softarm.harvest.control.actuator.SafeActuator(bank, pressure_map=...)``: the model's
        (true) elongations become pressures through each actuator's own gain."""
        return GainMap(max_psi, self.actuator_gain, self.actuator_offset)

    def predict(self, commands: npt.ArrayLike) -> F64:
        """End-effector poses (N, 4, 4) the fitted model predicts for ``commands``."""
        return self.arm.forward_batch(self.elongations(commands))

    def evaluate(self, commands: npt.ArrayLike, poses: npt.ArrayLike) -> PoseErrorStats:
        """Prediction errors against measured ``poses`` (N, 4, 4), e.g. held-out data."""
        pred = self.predict(commands)
        meas = np.asarray(poses, dtype=np.float64)
        if meas.shape != pred.shape:
            raise ShapeError(f"poses: expected shape {pred.shape}, got {meas.shape}")
        return PoseErrorStats.of(pred, meas)

    # --- model.toml -----------------------------------------------------------------

    def to_toml(self) -> str:
        """The text of ``model.toml``."""
        out = [
            "# softarm fitted arm model (softarm calibrate). SI units: metres, radians.",
            "# true elongation = actuators.gain x commanded elongation.",
            f"format = {FORMAT}",
            f"converged = {'true' if self.converged else 'false'}",
            "",
        ]
        for s in self.arm.sections:
            out += ["[[arm.sections]]"] + [f"{k} = {getattr(s, k)!r}" for k in _SECTION_KEYS]
            out.append("")
        out += ["[actuators]", f"gain = {[float(g) for g in self.actuator_gain]!r}"]
        offset = [float(o) for o in self.actuator_offset]
        out += [f"offset = {offset!r}", ""]
        out += ["[fit]"] + [f"{k} = {v!r}" for k, v in self.fit.as_dict().items()] + [""]
        out += ["[parameters]"]
        out += [f"{json.dumps(k)} = {float(v)!r}" for k, v in self.parameters.items()]
        return "\n".join(out) + "\n"

    def save(self, path: str | Path) -> None:
        """Write ``model.toml``."""
        write_text(path, self.to_toml(), "model file")

    @classmethod
    def load(cls, path: str | Path) -> Calibration:
        """Read a ``model.toml``; :class:`~softarm.errors.ConfigError` naming the file and
        the key when it cannot be read, is not TOML, or a value is malformed or out of
        its range (:mod:`softarm.calibration.model_file`)."""
        return cls.from_dict(load_toml(path, "model file"), str(path))

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "<model>") -> Calibration:
        """A Calibration from the parsed TOML of :meth:`to_toml`."""
        return cls(**model_fields(data, source))


class GainMap:
    """``ElongationMap`` with a gain and an offset per actuator:
    psi = (l - offset) / (gain x 1/2100 m/psi)."""

    def __init__(self, max_psi: float, gain: F64, offset: F64 | None = None) -> None:
        self.max_psi = float(max_psi)
        self.metres_per_psi = METRES_PER_PSI * np.asarray(gain, dtype=np.float64)
        self.offset = np.zeros_like(self.metres_per_psi) if offset is None else offset

    @property
    def max_elongation(self) -> F64:
        return self.max_psi * self.metres_per_psi + self.offset

    def to_psi(self, elongation: npt.ArrayLike, *, clamp: bool = True) -> F64:
        e = np.asarray(elongation, dtype=np.float64)
        if not np.all(np.isfinite(e)):
            raise NonFiniteError(f"elongation must be finite, got {e.tolist()!r}")
        psi = (e - self.offset) / self.metres_per_psi
        return np.clip(psi, 0.0, self.max_psi) if clamp else psi

    def to_elongation(self, psi: npt.ArrayLike, *, clamp: bool = True) -> F64:
        p = np.asarray(psi, dtype=np.float64)
        if not np.all(np.isfinite(p)):
            raise NonFiniteError(f"psi must be finite, got {p.tolist()!r}")
        return (np.clip(p, 0.0, self.max_psi) if clamp else p) * self.metres_per_psi + self.offset


def load_calibration(path: str | Path) -> Calibration:
    """The :class:`Calibration` saved in ``path`` (a ``model.toml``)."""
    return Calibration.load(path)


def load_model(path: str | Path) -> SoftArm:
    """The fitted arm of a ``model.toml``. Its elongations are *true* elongations: send
    ``calibration.commands_for(q)`` (q / gain) to the actuators, or accept the gains'
    few-percent error where the loop is closed on the measured pose."""
    return Calibration.load(path).arm
