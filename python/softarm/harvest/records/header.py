"""The header record that opens a harvest log and a harvest report (run metadata).

It says what made the run and how to read it: the softarm version and git commit, the
command and its arguments, the seed, the world (the simulated bush's canes and berries)
and the plant settings, the arm model the controller used, the cameras and markers as
frames, and the unit of every field of every record kind (:data:`UNITS`). With it a log
is self-contained: ``softarm replay`` and the ROS 2 bag (:mod:`softarm.viz.bag`) rebuild
the scene, the model and the frames from the log alone.
"""

from __future__ import annotations

import subprocess
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

import softarm
from softarm.units import MAX_PSI, METRES_PER_PSI

__all__ = [
    "FORMAT",
    "HEADER",
    "READABLE_FORMATS",
    "UNITS",
    "find_header",
    "git_commit",
    "header_record",
    "split_runs",
]

#: The kind of the header record.
HEADER = "header"
#: Version of the log's layout; a reader checks it before trusting the fields. 2: a
#: ``step``'s scalar fields carry their unit in their name (``target_age_s``,
#: ``position_error_m``, ``orientation_error_rad``); 1 had them bare
#: (:data:`softarm.harvest.records.log.STEP_RENAMED`, which
#: :func:`~softarm.harvest.records.log.read_log` applies to an older log).
FORMAT = 2
#: The formats a reader accepts (a format-1 log is read through ``read_log``'s renaming).
READABLE_FORMATS = (1, 2)
#: How long ``git rev-parse`` may take (s) before the commit is left out.
GIT_TIMEOUT_S = 2.0

#: The unit of every field, by record kind ("-" for names, flags and counts). Poses are
#: 4x4 homogeneous matrices in the base frame, positions in metres, times on the run's
#: clock in seconds (simulated time with --sim). The naming scheme: a scalar measurement
#: carries its unit as a suffix (``position_error_m``, ``duration_s``, ``*_mm``); the run
#: clock ``t`` (s) and the vectors and poses (``q``, ``pose``, ``target``, ``goal``, in m)
#: keep bare names, their units listed here.
UNITS: dict[str, dict[str, str]] = {
    HEADER: {
        "started_unix_ns": "ns since 1970-01-01 UTC",
        "seed": "-",
        "grasp_offset_m": "m",
        "arm.sections": "radius m, rest_length m, lower m, upper m, offset m, twist rad",
        "pressure_map": "psi = clip((q - offset_m) / metres_per_psi, 0, max_psi); m/psi, m, psi",
        "frames.*.pose": "4x4 pose in the parent frame (m)",
        "cameras.*": "width/height px, K px, D (plumb_bob, unitless)",
        "world.canes": "cubic coefficients (3x4) in u in [0, 1], base frame (m)",
        "world.berries.position": "m",
        "world.berries.ripeness": "0..1",
    },
    "step": {
        "t": "s",
        "q": "m (actuator elongations commanded)",
        "pose": "4x4 pose of the end effector measured by the cameras (m)",
        "target": "m (berry position estimate)",
        "target_age_s": "s",
        "goal": "m",
        "position_error_m": "m",
        "orientation_error_rad": "rad",
    },
    "transition": {"t": "s"},
    "fault": {"t": "s"},
    "vent": {"t": "s"},
    "plan": {"t": "s", "q": "m (one configuration per waypoint)", "axis": "unit vector",
             "berry": "m", "fell_back": "-", "standoff": "m"},
    "waypoint_handover": {"t": "s", "error": "m"},
    "waypoint_stalled": {"t": "s", "error": "m"},
    "transport_held": {"t": "s", "error": "m"},
    "fine_budget": {"t": "s", "error": "m"},
    "fine_confident": {"t": "s", "samples": "-", "error": "m", "bound": "m"},
    "limit_grasp": {"t": "s", "error": "m"},
    "lost_grasp": {"t": "s", "error": "m"},
    "placement_limit": {"t": "s", "error": "m", "pointing": "rad"},
    "ripeness": {"value": "0..1", "threshold": "0..1"},
    "berry_result": {"target": "m", "duration_s": "s", "*_mm": "mm", "*_deg": "deg"},
    "run_done": {"success_rate": "0..1"},
    "bush_map": {"t": "s", "berries.position": "m (base frame)", "berries.radius_m": "m",
                 "berries.ripe": "true: most sightings ripe", "canes.coeffs":
                 "cubic coefficients (3x4, ascending powers) in u in [0, 1], base frame (m)",
                 "canes.radius_m": "m"},
    "pressure_command": {"t": "s", "psi": "psi, one per channel (a vent: none)"},
}  # fmt: skip


def git_commit(where: str | Path | None = None) -> str | None:
    """The commit checked out where softarm's sources live (an editable install), with a
    ``-dirty`` suffix when they have local changes; None outside a git work tree."""
    root = Path(where if where is not None else Path(softarm.__file__).parent)
    try:
        head = _git(root, "rev-parse", "HEAD")
        dirty = _git(root, "status", "--porcelain", "--untracked-files=no", "--", ".")
    except (OSError, subprocess.SubprocessError):
        return None
    return None if head is None else head + ("-dirty" if dirty else "")


def _git(root: Path, *args: str) -> str | None:
    out = subprocess.run(
        ["git", "-C", str(root), *args],
        capture_output=True,
        text=True,
        timeout=GIT_TIMEOUT_S,
        check=False,
    )
    return out.stdout.strip() if out.returncode == 0 else None


def header_record(
    command: str, argv: Sequence[str], options: Mapping[str, Any], **settings: Any
) -> dict[str, Any]:
    """The header's fields (without ``kind``): version, commit, start time, the command,
    its arguments (``argv`` as typed, ``options`` as parsed), the run's ``settings``
    (seed, world, plant, arm, frames, cameras:
    :func:`softarm.harvest.rigs.sim.header.sim_settings`) and :data:`UNITS`."""
    return {
        "format": FORMAT,
        "softarm": softarm.__version__,
        "commit": git_commit(),
        "started_unix_ns": time.time_ns(),
        "command": command,
        "argv": list(argv),
        "options": {k: _plain_option(v) for k, v in options.items() if k != "run"},
        **settings,
        "units": UNITS,
    }


def _plain_option(value: Any) -> Any:
    """A parsed option as JSON: paths as strings, anything else not JSON as its repr."""
    if value is None or isinstance(value, bool | int | float | str):
        return value
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, list | tuple):
        return [_plain_option(v) for v in value]
    return repr(value)


def arm_settings(arm: Any) -> dict[str, Any]:
    """``arm`` (a SoftArm) as its sections' parameters, in the order of ``Section``."""
    rows = [[s.radius, s.rest_length, s.lower, s.upper, s.offset, s.twist] for s in arm.sections]
    return {"sections": rows}


def world_settings(
    bush: Any, unripe_fraction: float, kind: str = "tags", canes: Sequence[Any] | None = None
) -> dict[str, Any]:
    """The simulated bush (``kind``: ``--world``): its seed, canes (cubic coefficients:
    ``canes``, every cane the world draws, each with ``coeffs``; None: the bush's) and
    berries."""
    drawn = bush.branches if canes is None else canes
    return {
        "source": "sim",
        "kind": kind,
        "seed": bush.seed,
        "unripe_fraction": unripe_fraction,
        "canes": [np.asarray(c.coeffs) for c in drawn],
        "berries": [
            {"tag_id": b.tag_id, "position": np.asarray(b.position), "ripeness": b.ripeness}
            for b in bush.berries
        ],
    }


def pressure_settings(pmap: Any, n: int) -> dict[str, Any]:
    """How the commanded elongations became pressures: ``pmap`` (an ``ElongationMap``
    or a calibration's ``GainMap``; None: the nominal 1/2100 m/psi up to 70 psi)."""
    mpp = METRES_PER_PSI if pmap is None else pmap.metres_per_psi
    offset = getattr(pmap, "offset", 0.0)
    return {
        "max_psi": MAX_PSI if pmap is None else float(pmap.max_psi),
        "metres_per_psi": np.broadcast_to(np.asarray(mpp, dtype=np.float64), (n,)),
        "offset_m": np.broadcast_to(np.asarray(offset, dtype=np.float64), (n,)),
    }


def frame(parent: str, pose: Any) -> dict[str, Any]:
    """A fixed frame: its parent's name and its 4x4 pose in that parent."""
    return {"parent": parent, "pose": np.asarray(pose, dtype=np.float64)}


def camera(model: Any) -> dict[str, Any]:
    """A camera's intrinsics (a ``softarm.vision.CameraModel`` with an image size)."""
    width, height = model.image_size or (0, 0)
    return {
        "width": int(width),
        "height": int(height),
        "K": np.asarray(model.matrix),
        "D": np.asarray(model.distortion).ravel(),
    }


def hardware_settings(config: Any, config_path: str | Path) -> dict[str, Any]:
    """The settings of a hardware run on ``config`` (a loaded ``softarm.config.Config``):
    the rig has no simulated world, and the plant is the arm itself."""
    from softarm.hardware.pressure_map import ElongationMap
    from softarm.vision.camera_model import camera_from_config
    from softarm.vision.poses import invert

    cal, ch = config.calibration, config.channels
    arm = softarm.SoftArm.from_config(config)
    frames = {"cube": frame("gripper", cal.T_EE_cube)}
    if cal.T_C1_base is not None:
        frames["camera_c1"] = frame("base", invert(np.array(cal.T_C1_base)))
    if cal.T_C2_EE is not None:
        frames["camera_c2"] = frame("gripper", invert(np.array(cal.T_C2_EE)))
    cameras = {}
    for name, cam in (("c1", cal.c1), ("c2", cal.c2)):
        if cam.file is not None or cam.matrix is not None:
            cameras[f"camera_{name}"] = camera(camera_from_config(cam, name))
    pmap = ElongationMap(ch.p_max, ch.metres_per_psi)
    return {
        "seed": None,
        "config_file": str(config_path),
        "world": {"source": "hardware"},
        "plant": {"model": "hardware"},
        "arm": arm_settings(arm),
        "grasp_offset_m": config.harvest.grasp_offset,
        "pressure_map": pressure_settings(pmap, arm.n_actuators),
        "frames": frames,
        "cameras": cameras,
    }


def find_header(records: Iterable[Any]) -> dict[str, Any] | None:
    """The first header record of ``records`` (the log's own), or None (an older log)."""
    for r in records:
        if isinstance(r, dict) and r.get("kind") == HEADER:
            return r
    return None


def split_runs(records: Sequence[Any]) -> list[list[Any]]:
    """The runs of a log that ``--log`` appended to more than once: each header record
    opens a run. Records before the first header are a run of their own (an older log's,
    written before the header existed), unless they are only the mark of a cut-off line
    (:data:`softarm.harvest.records.log.CUT_MARK`, which an appending run writes first)."""
    from softarm.harvest.records.log import CUT_MARK

    runs: list[list[Any]] = [[]]
    for r in records:
        if isinstance(r, dict) and r.get("kind") == HEADER:
            runs.append([])
        runs[-1].append(r)
    first = [r for r in runs[0] if not (isinstance(r, dict) and r.get("kind") == CUT_MARK)]
    return runs if first or len(runs) == 1 else runs[1:]
