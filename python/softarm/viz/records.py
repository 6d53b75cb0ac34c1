"""Harvest run-log records (:mod:`softarm.harvest.records.log`) drawn in a rerun recording.

One record at a time, on the ``sim_time`` timeline at the record's own ``t`` (the time its
step observed; a record without one, e.g. ``ripeness``, goes at the last time seen). The
same code serves the live view (records drained as the machine writes them) and
``softarm replay`` (records read back from a JSON-lines file), so both show the same:

* ``world/arm/model``: the model arm at the commanded elongations ``q`` (the soft arm has
  no joint sensors: this is what the controller believes), with its gripper;
* ``world/estimate/ee``: the end-effector frame the eye-to-hand camera measured (eq. 22);
* ``world/estimate/berry``: the fused berry position, labelled by tag and camera;
* ``world/goal``, ``world/plan``: the servo's goal and the planned tip path;
* ``harvest/state`` (text) and ``harvest/state_index`` (scalar): the state machine;
* ``errors/*``: position and pointing errors as the cameras measured them, the true ones
  at each grasp, the age of the berry fix.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.errors import InputError, ShapeError
from softarm.harvest.machine.states import HarvestState
from softarm.viz.arm import arm_polylines
from softarm.viz.gripper import gripper_outline
from softarm.viz.rerun_sdk import TIMELINE

__all__ = ["STATE_INDEX", "ArmDrawer", "RecordLogger"]


#: The states as numbers for the state plot, in the order of the workflow (fig. 4).
STATE_INDEX: dict[str, int] = {s.value: i for i, s in enumerate(HarvestState)}

#: Section colours (RGB): proximal red, medial green, distal blue as in the paper's figures.
SECTION_RGB = ((214, 39, 40), (44, 160, 44), (31, 119, 180), (148, 103, 189), (255, 127, 14))

#: The error series and their colours.
SERIES = {
    "position_mm": (31, 119, 180),
    "pointing_deg": (255, 127, 14),
    "true_position_mm": (44, 160, 44),
    "target_age_s": (127, 127, 127),
}

#: Events drawn as warnings or errors in the text log.
_LEVELS = {
    "fault": "ERROR",
    "crash": "ERROR",
    "vent": "WARN",
    "vent_failed": "ERROR",
    "interrupted": "WARN",
    "run_stopped": "WARN",
    "retreat_incomplete": "WARN",
    "fine_budget": "WARN",
    "placement_limit": "WARN",
    "limit_grasp": "WARN",
    "lost_grasp": "WARN",
}


def as_vector(value: Any, name: str, length: int | None = None) -> FloatArray:
    """``value`` as a finite float vector (of ``length`` when given), or a typed error
    naming the field."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a list of numbers, got {value!r}") from None
    if arr.ndim != 1 or (length is not None and arr.size != length):
        want = f"{length} numbers" if length is not None else "a flat list of numbers"
        raise ShapeError(f"{name} must be {want}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} holds a non-finite value: {value!r}")
    return arr


def as_pose(value: Any, name: str) -> FloatArray:
    """``value`` as a finite 4x4 matrix, or a typed error naming the field."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a 4x4 matrix, got {value!r}") from None
    if arr.shape != (4, 4) or not np.all(np.isfinite(arr)):
        raise ShapeError(f"{name} must be a finite 4x4 matrix, got shape {arr.shape}")
    return arr


class ArmDrawer:
    """Draws one arm (backbone per section and gripper) under ``path`` in a recording.

    The gripper's outline is logged once, statically, in the end-effector frame; each
    update only moves that frame (``path/gripper``), as rerun's transform hierarchy
    intends.
    """

    def __init__(
        self,
        stream: Any,
        rr: Any,
        path: str,
        n_sections: int,
        samples: int = 20,
        grasp_offset: float = 0.03,
        alpha: int = 255,
        width: float = 0.006,
    ) -> None:
        self.stream, self.rr, self.path = stream, rr, path
        self.n_sections, self.samples = n_sections, samples
        self.colours = [(*SECTION_RGB[i % len(SECTION_RGB)], alpha) for i in range(n_sections)]
        self.radius = width / 2
        stream.log(
            f"{path}/gripper/outline",
            rr.LineStrips3D(
                gripper_outline(grasp_offset), colors=[(90, 90, 90, alpha)], radii=self.radius / 2
            ),
            static=True,
        )
        stream.log(
            f"{path}/gripper/grasp_point",
            rr.Points3D([[0.0, 0.0, grasp_offset]], colors=[(250, 200, 0, alpha)], radii=0.003),
            static=True,
        )
        stream.log(f"{path}/gripper", rr.TransformAxes3D(0.03), static=True)

    def draw(self, backbone: FloatArray, pose: FloatArray) -> None:
        """``backbone``: any (n, 3) centre line (one strip, e.g. a Cosserat rod's);
        ``pose``: the end effector's 4x4 pose."""
        self._log([np.asarray(backbone, dtype=np.float64)], self.colours[:1], pose)

    def draw_arm(self, arm: Any, q: FloatArray) -> None:
        """The arm at ``q``: one colour per section, the rigid links (plates, the
        gripper's body) grey, and the gripper at the end-effector frame."""
        arcs, links = arm_polylines(arm, q, self.samples)
        grey = (110, 110, 110, self.colours[0][3])
        self._log([*arcs, *links], [*self.colours, *[grey] * len(links)],
                  np.asarray(arm.forward(q)))  # fmt: skip

    def _log(self, strips: list[FloatArray], colours: list[Any], pose: FloatArray) -> None:
        rr = self.rr
        self.stream.log(
            f"{self.path}/backbone", rr.LineStrips3D(strips, colors=colours, radii=self.radius)
        )
        self.stream.log(
            f"{self.path}/gripper", rr.Transform3D(translation=pose[:3, 3], mat3x3=pose[:3, :3])
        )


class RecordLogger:
    """Logs run-log records to ``stream`` (see the module docstring).

    Args:
        stream: a ``rerun.RecordingStream`` (:func:`~softarm.viz.rerun_sdk.open_recording`).
        rr: the ``rerun`` module.
        model: the arm the controller uses (``q`` is drawn on it); None draws no model arm.
        grasp_offset: the grasp point ahead of the end effector (m).
        berries_from_results: draw ``world/berries`` from the ``berry_result`` records
            (a replay has no bush; the live view draws the true berries itself).
    """

    def __init__(
        self,
        stream: Any,
        rr: Any,
        model: Any | None = None,
        grasp_offset: float = 0.03,
        berries_from_results: bool = False,
    ) -> None:
        self.stream, self.rr, self.model = stream, rr, model
        self.t = 0.0
        self.count = 0
        self.berries_from_results = berries_from_results
        self._results: dict[int, tuple[FloatArray, bool]] = {}
        self._arm = (
            None
            if model is None
            else ArmDrawer(
                stream,
                rr,
                "world/arm/model",
                model.n_sections,
                20,
                grasp_offset,
                alpha=150,
                width=0.004,
            )
        )
        stream.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        stream.log("world/estimate/ee", rr.TransformAxes3D(0.025), static=True)
        for name, colour in SERIES.items():
            stream.log(f"errors/{name}", rr.SeriesLines(colors=colour, names=name), static=True)
        stream.log("harvest/state_index", rr.SeriesLines(names="state"), static=True)

    def log(self, record: Mapping[str, Any]) -> None:
        """Draw one record; raises :class:`~softarm.errors.InputError` for a malformed one
        (its message names the field)."""
        if not isinstance(record, Mapping) or not isinstance(record.get("kind"), str):
            raise InputError(f"a record must be an object with a string 'kind', got {record!r}")
        t = record.get("t")
        if t is not None:
            self.t = _seconds(t)
        self.stream.set_time(TIMELINE, duration=self.t)
        # An explicit table: a record's kind must not reach any other attribute.
        handler = _HANDLERS.get(record["kind"])
        if handler is not None:
            handler(self, record)
        else:
            self._text(record, "harvest/log")
        self.count += 1

    # One method per record kind (the name after the underscore).

    def _step(self, r: Mapping[str, Any]) -> None:
        rr, log = self.rr, self.stream.log
        state = r.get("state")
        if state is not None and not isinstance(state, str):
            raise InputError(f"state must be a state name, got {state!r}")
        if state in STATE_INDEX:
            log("harvest/state_index", rr.Scalars(STATE_INDEX[state]))
        if self.model is not None and r.get("q") is not None:
            q = as_vector(r["q"], "q", self.model.n_actuators)
            assert self._arm is not None
            self._arm.draw_arm(self.model, q)
        if r.get("pose") is not None:
            pose = as_pose(r["pose"], "pose")
            log("world/estimate/ee", rr.Transform3D(translation=pose[:3, 3], mat3x3=pose[:3, :3]))
        if r.get("target") is not None:
            target = as_vector(r["target"], "target", 3)
            label = f"tag {r.get('berry')} ({r.get('camera')})"
            log(
                "world/estimate/berry",
                rr.Points3D([target], labels=[label], radii=0.006, colors=[(255, 0, 255)]),
            )
        if r.get("goal") is not None:
            goal = as_vector(r["goal"], "goal", 3)
            log("world/goal", rr.Points3D([goal], radii=0.004, colors=[(250, 200, 0)]))
        for field, name, scale in (
            ("position_error_m", "position_mm", 1e3),
            ("orientation_error_rad", "pointing_deg", 180.0 / np.pi),
            ("target_age_s", "target_age_s", 1.0),
        ):
            value = r.get(field)
            if value is not None:
                log(f"errors/{name}", rr.Scalars(scale * float(as_vector([value], field)[0])))

    def _transition(self, r: Mapping[str, Any]) -> None:
        new = r.get("new")
        level = "ERROR" if new == "fault" else "INFO"
        text = f"tag {r.get('berry')}: {r.get('old')} -> {new} ({r.get('why')})"
        self.stream.log("harvest/state", self.rr.TextLog(text, level=level))
        if isinstance(new, str) and new in STATE_INDEX:
            self.stream.log("harvest/state_index", self.rr.Scalars(STATE_INDEX[new]))

    def _plan(self, r: Mapping[str, Any]) -> None:
        rr = self.rr
        if self.model is not None and r.get("q"):
            if not isinstance(r["q"], list):
                raise InputError(f"plan q must be a list of configurations, got {r['q']!r}")
            tips = [
                self.model.forward(as_vector(q, "plan q", self.model.n_actuators))[:3, 3]
                for q in r["q"]
            ]
            self.stream.log(
                "world/plan", rr.LineStrips3D([tips], colors=[(250, 200, 0)], radii=0.002)
            )
        self._text(r, "harvest/log", skip=("q",))

    def _header(self, r: Mapping[str, Any]) -> None:
        """The run's header (softarm.harvest.records.header) as one line: what made the run."""
        argv = r.get("argv")
        words = " ".join(str(a) for a in argv) if isinstance(argv, list) else ""
        text = (
            f"softarm {r.get('softarm')} (commit {r.get('commit') or 'unknown'}): "
            f"softarm {words}; seed {r.get('seed')}"
        )
        self.stream.log("harvest/log", self.rr.TextLog(text, level="INFO"))

    def _ripeness(self, r: Mapping[str, Any]) -> None:
        self._text(r, "harvest/log")

    def _berry_result(self, r: Mapping[str, Any]) -> None:
        err = r.get("true_position_error_mm")
        if err is not None:
            mm = float(as_vector([err], "true_position_error_mm")[0])
            self.stream.log("errors/true_position_mm", self.rr.Scalars(mm))
        what = "harvested" if r.get("harvested") else (r.get("fault") or "not harvested")
        text = f"tag {r.get('tag_id')}: {what}, {r.get('duration_s')} s, {r.get('steps')} steps"
        level = "INFO" if r.get("harvested") else "WARN"
        self.stream.log("harvest/state", self.rr.TextLog(text, level=level))
        if self.berries_from_results and r.get("target") is not None:
            tag = r.get("tag_id")
            if not isinstance(tag, int):
                raise InputError(f"tag_id must be an integer, got {tag!r}")
            self._results[tag] = (as_vector(r["target"], "target", 3), bool(r.get("harvested")))
            self._draw_result_berries()

    def _draw_result_berries(self) -> None:
        tags = sorted(self._results)
        pts = [self._results[t][0] for t in tags]
        colours = [(40, 160, 40) if self._results[t][1] else (214, 39, 40) for t in tags]
        self.stream.log(
            "world/berries",
            self.rr.Points3D(
                pts, labels=[f"tag {t}" for t in tags], colors=colours, radii=0.01, show_labels=True
            ),
        )

    def _text(self, r: Mapping[str, Any], path: str, skip: tuple[str, ...] = ()) -> None:
        fields = {k: v for k, v in r.items() if k not in ("kind", "t", *skip)}
        text = f"{r['kind']}: {json.dumps(fields, default=str)}"
        self.stream.log(path, self.rr.TextLog(text, level=_LEVELS.get(r["kind"], "INFO")))


def _seconds(t: Any) -> float:
    """A record's time ``t``: a finite number (a bool, a string or an integer too large
    for a float is an InputError)."""
    try:
        ok = isinstance(t, int | float) and not isinstance(t, bool) and math.isfinite(t)
    except OverflowError:
        ok = False
    if not ok:
        raise InputError(f"t must be a finite number of seconds, got {str(t)[:40]!r}")
    return float(t)


#: The drawing of each record kind; any other kind is shown as text.
_HANDLERS: dict[str, Callable[[RecordLogger, Mapping[str, Any]], None]] = {
    "step": RecordLogger._step,
    "transition": RecordLogger._transition,
    "plan": RecordLogger._plan,
    "ripeness": RecordLogger._ripeness,
    "berry_result": RecordLogger._berry_result,
    "header": RecordLogger._header,
}
