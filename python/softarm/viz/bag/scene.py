"""What a bag draws besides the records: the arm model, the fixed frames, the cameras,
the canes and the berries, and the pressure map, read from the log's header record
(:mod:`softarm.harvest.records.header`). A log without a header (written before it existed) gets
the nominal blackberry arm and the simulated rig's cameras, and no bush."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

import softarm
from softarm.checks import FloatArray
from softarm.errors import InputError
from softarm.harvest.records.header import READABLE_FORMATS
from softarm.sim.bush import Branch
from softarm.units import MAX_PSI, METRES_PER_PSI
from softarm.viz.bag.messages import NS_PER_S
from softarm.viz.records import as_pose, as_vector

__all__ = [
    "CAMERAS",
    "CANE_SAMPLES",
    "MAX_STAMP_NS",
    "BerryMark",
    "RunScene",
    "cane_branch",
    "stamp_ns",
]

#: Points along each cane's line strip.
CANE_SAMPLES = 40
#: The cameras a header may describe (each has its topics in the bag).
CAMERAS = ("camera_c1", "camera_c2")
#: The largest image side a header camera may have (pixels).
MAX_PIXELS = 65535
#: The last stamp a bag can hold: builtin_interfaces/Time keeps seconds in an int32.
MAX_STAMP_NS = 2**31 * NS_PER_S - 1


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
            grasp_offset=_number(header.get("grasp_offset_m", 0.03), "header grasp_offset_m"),
            frames={k: _frame(k, v) for k, v in (header.get("frames") or {}).items()},
            cameras=_cameras(header.get("cameras")),
            branches=[_cane(c) for c in world.get("canes", [])],
            berries=[_berry(b) for b in world.get("berries", [])],
            pressure=_pressure(header.get("pressure_map")),
            start_ns=_start(header.get("started_unix_ns", 0)),
            source=str(world.get("source", "sim")),
        )

    @classmethod
    def _defaults(cls) -> RunScene:
        from softarm.harvest.records.header import camera
        from softarm.harvest.rigs.sim.options import default_cameras

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
    if not isinstance(value, Mapping):
        raise InputError(f"header pressure_map must be an object, got {value!r:.60}")
    mpp = as_vector(value.get("metres_per_psi"), "header pressure_map.metres_per_psi")
    offset = as_vector(value.get("offset_m", [0.0]), "header pressure_map.offset_m")
    if not np.all(mpp > 0):
        raise InputError("header pressure_map.metres_per_psi must be positive")
    return _number(value.get("max_psi", MAX_PSI), "header pressure_map.max_psi"), mpp, offset


def _number(value: Any, name: str) -> float:
    return float(as_vector([value], name)[0])


def _start(value: Any) -> int:
    """The header's start time: a non-negative integer of ns since the epoch, within
    what a bag's stamps hold (:data:`MAX_STAMP_NS`)."""
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= MAX_STAMP_NS:
        raise InputError(
            f"header started_unix_ns must be an integer of ns from 0 to {MAX_STAMP_NS} "
            f"(a ROS 2 stamp keeps its seconds in 32 bits), got {str(value)[:40]}"
        )
    return value


def stamp_ns(start_ns: int, t: float) -> int:
    """The stamp (ns since the epoch) of the time ``t`` (s, finite) of a run that
    started at ``start_ns``; an InputError where a bag cannot hold it."""
    ns = start_ns + round(t * NS_PER_S) if abs(t) <= MAX_STAMP_NS / NS_PER_S else -1
    if not 0 <= ns <= MAX_STAMP_NS:
        raise InputError(
            f"t = {t!r} s from the run's start gives a stamp outside 0..{MAX_STAMP_NS} ns "
            "(a ROS 2 stamp keeps its seconds in 32 bits)"
        )
    return ns


def _cameras(value: Any) -> dict[str, Mapping[str, Any]]:
    """The header's cameras: ``camera_c1`` and/or ``camera_c2``, each with an image
    size (0 x 0: unknown), a 3 x 3 ``K`` and distortion ``D``, all finite."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise InputError(f"header cameras must be an object, got {value!r:.60}")
    return {name: _camera(name, camera) for name, camera in value.items()}


def _camera(name: Any, value: Any) -> dict[str, Any]:
    where = f"header cameras.{name}"
    if name not in CAMERAS:
        raise InputError(f"{where}: the cameras are {' and '.join(CAMERAS)}")
    if not isinstance(value, Mapping):
        raise InputError(f"{where} must hold width, height, K and D, got {value!r:.60}")
    size: list[Any] = [value.get("width"), value.get("height")]
    whole = all(isinstance(v, int) and not isinstance(v, bool) for v in size)
    if not (whole and all(0 <= v <= MAX_PIXELS for v in size)):
        raise InputError(f"{where}: width and height must be integers 0..{MAX_PIXELS}, got {size}")
    K = as_vector(np.ravel(_array(value.get("K"), f"{where}.K")), f"{where}.K", 9)
    D = as_vector(np.ravel(_array(value.get("D", []), f"{where}.D")), f"{where}.D")
    return {"width": size[0], "height": size[1], "K": K.reshape(3, 3), "D": D}


def _array(value: Any, name: str) -> Any:
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers, got {value!r:.60}") from None
