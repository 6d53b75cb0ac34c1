"""What a bag draws besides the records: the arm model, the fixed frames, the cameras,
the canes and the berries, and the pressure map, read from the log's header record
(:mod:`softarm.harvest.header`). A log without a header (written before it existed) gets
the nominal blackberry arm and the simulated rig's cameras, and no bush."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

import softarm
from softarm.checks import FloatArray
from softarm.errors import InputError
from softarm.harvest.header import READABLE_FORMATS
from softarm.sim.bush import Branch
from softarm.units import MAX_PSI, METRES_PER_PSI
from softarm.viz.records import as_pose, as_vector

__all__ = ["CANE_SAMPLES", "BerryMark", "RunScene", "cane_branch"]

#: Points along each cane's line strip.
CANE_SAMPLES = 40


@dataclass(frozen=True)
class BerryMark:
    """A berry of the world: its tag, position (m) and ripeness (0..1)."""

    tag_id: int
    position: FloatArray
    ripeness: float


@dataclass(frozen=True)
class RunScene:
    """The fixed part of a run (see the module docstring)."""

    arm: softarm.SoftArm
    grasp_offset: float = 0.03
    #: name -> (parent frame, 4x4 pose in the parent).
    frames: dict[str, tuple[str, FloatArray]] = field(default_factory=dict)
    #: name -> {"width", "height", "K", "D"}.
    cameras: dict[str, Mapping[str, Any]] = field(default_factory=dict)
    #: The canes (``softarm.sim.bush.Branch``: cubic coefficients).
    branches: list[Branch] = field(default_factory=list)
    berries: list[BerryMark] = field(default_factory=list)
    #: (max_psi, metres_per_psi per actuator, offset per actuator in m).
    pressure: tuple[float, FloatArray, FloatArray] = (
        MAX_PSI,
        np.array(METRES_PER_PSI),
        np.zeros(1),
    )
    #: The run's start (ns since the epoch): the bag's stamps are this plus the record's t.
    start_ns: int = 0
    #: "sim" or "hardware" (the diagnostics' hardware id).
    source: str = "sim"

    @classmethod
    def from_header(cls, header: Mapping[str, Any] | None) -> RunScene:
        """The scene a header record describes (None: the defaults of an older log)."""
        if header is None:
            return cls._defaults()
        fmt = header.get("format")
        if isinstance(fmt, bool) or fmt not in READABLE_FORMATS:
            formats = " or ".join(map(str, READABLE_FORMATS))
            raise InputError(f"header format must be {formats}, got {fmt!r}")
        world = header.get("world") or {}
        if not isinstance(world, Mapping):
            raise InputError(f"header world must be an object, got {world!r:.60}")
        return cls(
            arm=_arm(header.get("arm")),
            grasp_offset=float(header.get("grasp_offset_m", 0.03)),
            frames={k: _frame(k, v) for k, v in (header.get("frames") or {}).items()},
            cameras=dict(header.get("cameras") or {}),
            branches=[_cane(c) for c in world.get("canes", [])],
            berries=[_berry(b) for b in world.get("berries", [])],
            pressure=_pressure(header.get("pressure_map")),
            start_ns=_start(header.get("started_unix_ns", 0)),
            source=str(world.get("source", "sim")),
        )

    @classmethod
    def _defaults(cls) -> RunScene:
        from softarm.harvest.header import camera
        from softarm.harvest.sim_rig import default_cameras

        cams = default_cameras()
        return cls(
            arm=softarm.SoftArm.blackberry(),
            frames={
                "camera_c1": ("base", cams.T_base_c1),
                "camera_c2": ("gripper", cams.T_ee_c2),
                "cube": ("gripper", cams.T_ee_cube),
            },
            cameras={"camera_c1": camera(cams.model(1)), "camera_c2": camera(cams.model(2))},
        )

    @property
    def canes(self) -> list[FloatArray]:
        """Each cane as (CANE_SAMPLES, 3) points (m, base frame)."""
        return [b.points(CANE_SAMPLES) for b in self.branches]

    def pressures(self, q: FloatArray) -> FloatArray:
        """The pressures (psi) the actuators were sent for elongations ``q`` (m)."""
        max_psi, mpp, offset = self.pressure
        return np.clip((q - offset) / mpp, 0.0, max_psi)


def _arm(value: Any) -> softarm.SoftArm:
    if value is None:
        return softarm.SoftArm.blackberry()
    rows = value.get("sections") if isinstance(value, Mapping) else None
    if not isinstance(rows, list) or not rows:
        raise InputError(f"header arm.sections must be a list of sections, got {rows!r}")
    return softarm.SoftArm([softarm.Section(*as_vector(r, "header arm.sections", 6)) for r in rows])


def _frame(name: str, value: Any) -> tuple[str, FloatArray]:
    if not isinstance(value, Mapping) or not isinstance(value.get("parent"), str):
        raise InputError(f"header frames.{name} must hold a parent name and a pose")
    return value["parent"], as_pose(value.get("pose"), f"header frames.{name}.pose")


def _cane(coeffs: Any) -> Branch:
    return cane_branch(coeffs, "header world.canes")


def cane_branch(coeffs: Any, name: str) -> Branch:
    """A cane of 3 x k polynomial coefficients (ascending powers of u in [0, 1]);
    ``name`` says where it came from in the error."""
    try:
        c = np.asarray(coeffs, dtype=np.float64)
    except (TypeError, ValueError):
        c = np.zeros(0)
    if c.ndim != 2 or c.shape[0] != 3 or not np.all(np.isfinite(c)):
        raise InputError(f"{name}: each cane must be 3 x k coefficients, got {c.shape}")
    return Branch(c)


def _berry(value: Any) -> BerryMark:
    if not isinstance(value, Mapping) or not isinstance(value.get("tag_id"), int):
        raise InputError(f"header world.berries: each needs an integer tag_id, got {value!r}")
    ripeness = float(as_vector([value.get("ripeness", 1.0)], "ripeness")[0])
    return BerryMark(
        value["tag_id"], as_vector(value.get("position"), "berry position", 3), ripeness
    )


def _pressure(value: Any) -> tuple[float, FloatArray, FloatArray]:
    if value is None:
        return MAX_PSI, np.array(METRES_PER_PSI), np.zeros(1)
    mpp = as_vector(value.get("metres_per_psi"), "header pressure_map.metres_per_psi")
    offset = as_vector(value.get("offset_m", [0.0]), "header pressure_map.offset_m")
    if not np.all(mpp > 0):
        raise InputError("header pressure_map.metres_per_psi must be positive")
    return float(value.get("max_psi", MAX_PSI)), mpp, offset


def _start(value: Any) -> int:
    """The header's start time: a non-negative integer of ns since the epoch."""
    if not isinstance(value, int) or isinstance(value, bool) or value < 0:
        raise InputError(f"header started_unix_ns must be a non-negative integer, got {value!r}")
    return value
