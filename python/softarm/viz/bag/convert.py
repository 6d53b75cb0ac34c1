"""Run-log records (:mod:`softarm.harvest.records.log`) as ROS 2 messages on their topics.

The stamps are the run's start (from the header) plus each record's ``t``; a record
without one (``ripeness``, ``berry_result``) takes the last time seen, and the clock never
runs backwards, so every topic's stamps are monotonic. Steps logged at the same ``t``
(a stage ending and the next starting) are one message: the last one wins. A step's
markers draw the latest ``bush_map`` logged at or before its time (what perception found).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.errors import InputError
from softarm.harvest.records.header import HEADER, find_header
from softarm.viz.bag.markers import scene_markers
from softarm.viz.bag.messages import Messages
from softarm.viz.bag.scene import CANE_SAMPLES, RunScene, cane_branch, stamp_ns
from softarm.viz.records import _LEVELS, _seconds, as_pose, as_vector

__all__ = ["TOPICS", "Converter", "Detection", "Message", "actuator_names"]

#: Topic -> message type of every topic a bag of the log alone may hold (a camera's only
#: when the header describes it); recorded frames add
#: :data:`softarm.viz.bag.images.IMAGE_TOPICS`.
TOPICS: dict[str, str] = {
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/pressure_command": "std_msgs/msg/Float64MultiArray",
    "/camera_c1/camera_info": "sensor_msgs/msg/CameraInfo",
    "/camera_c2/camera_info": "sensor_msgs/msg/CameraInfo",
    "/harvest/markers": "visualization_msgs/msg/MarkerArray",
    "/harvest/state": "std_msgs/msg/String",
    "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
    "/rosout": "rcl_interfaces/msg/Log",
}
#: The node name on /rosout and the diagnostics' status name.
NODE = "softarm_harvest"


@dataclass(frozen=True)
class Message:
    """One message for the bag: its topic, stamp (ns since the epoch) and the message."""

    topic: str
    ns: int
    msg: Any


@dataclass(frozen=True)
class Detection:
    """A berry of a ``bush_map`` record: its map id, position (m, base frame), radius
    (m) and perceived ripeness."""

    id: int
    position: FloatArray
    radius: float
    ripe: bool


@dataclass
class DrawState:
    """What the markers show at the current time."""

    q: FloatArray | None = None
    estimate: FloatArray | None = None
    goal: FloatArray | None = None
    plan: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    picked: set[int] = field(default_factory=set)
    #: The latest bush map's berries, and its fitted canes as (points, radius m).
    detections: list[Detection] = field(default_factory=list)
    fitted: list[tuple[FloatArray, float]] = field(default_factory=list)
    #: Every detection id and the most fitted canes any map so far drew (to delete).
    drawn_ids: set[int] = field(default_factory=set)
    fitted_slots: int = 0


def actuator_names(n_sections: int, per_section: int = 3) -> list[str]:
    """``section_1_actuator_1`` ... : the joint names of /joint_states."""
    return [
        f"section_{s + 1}_actuator_{a + 1}" for s in range(n_sections) for a in range(per_section)
    ]


class Converter:
    """Turns the records of one run into :class:`Message` s (see the module docstring)."""

    def __init__(self, m: Messages, scene: RunScene) -> None:
        self.m, self.scene = m, scene
        self.names = actuator_names(
            scene.arm.n_sections, scene.arm.n_actuators // scene.arm.n_sections
        )
        self.draw = DrawState()
        self.t = 0.0
        self._pending: tuple[float, Mapping[str, Any]] | None = None

    @classmethod
    def for_records(cls, m: Messages, records: list[Any]) -> Converter:
        return cls(m, RunScene.from_header(find_header(records)))

    def ns(self, t: float) -> int:
        return stamp_ns(self.scene.start_ns, t)

    def messages(self, records: Iterable[Any]) -> Iterator[Message]:
        """Every message of ``records``, the fixed frames first."""
        yield self.static_frames()
        for n, record in enumerate(records, start=1):
            try:
                yield from self.record(record)
            except InputError as exc:
                raise type(exc)(f"record {n}: {exc}") from None
        yield from self._flush()

    def static_frames(self) -> Message:
        """/tf_static: the cameras, the cube and the grasp point, and the gripper at the
        end of the last section."""
        grasp = np.eye(4)
        grasp[2, 3] = self.scene.grasp_offset
        last = f"section_{self.scene.arm.n_sections}"
        fixed = [(last, "gripper", np.eye(4)), ("gripper", "grasp_point", grasp)]
        fixed += [(parent, child, pose) for child, (parent, pose) in self.scene.frames.items()]
        ns = self.ns(0.0)
        return Message("/tf_static", ns, self.m.tf([self.m.transform(ns, *f) for f in fixed]))

    def record(self, r: Any) -> Iterator[Message]:
        """The messages of one record (a step's wait for the next record's time)."""
        if not isinstance(r, Mapping) or not isinstance(r.get("kind"), str):
            raise InputError(f"a record must be an object with a string 'kind', got {r!r:.60}")
        if r.get("t") is not None:
            t = _seconds(r["t"])
            if self._pending is not None and t > self._pending[0]:
                yield from self._flush()
            self.t = max(self.t, t)
            self.ns(self.t)  # a stamp the bag cannot hold is named with this record
        if r["kind"] == "step":
            self._pending = (self.t, self._checked_step(r))
            return
        if r["kind"] == HEADER:
            return
        yield from self._event(r)

    def _flush(self) -> Iterator[Message]:
        if self._pending is not None:
            t, r = self._pending
            self._pending = None
            yield from self._step(self.ns(t), r)

    def _checked_step(self, r: Mapping[str, Any]) -> dict[str, Any]:
        """A step with its vectors checked (an error names this record, not the next)."""
        out = dict(r)
        for key, length in (("target", 3), ("goal", 3), ("q", self.scene.arm.n_actuators)):
            if r.get(key) is not None:
                out[key] = as_vector(r[key], key, length)
        if r.get("pose") is not None:
            out["pose"] = as_pose(r["pose"], "pose")
        return out

    def _step(self, ns: int, r: Mapping[str, Any]) -> Iterator[Message]:
        m, d = self.m, self.draw
        if r.get("q") is not None:
            d.q = r["q"]
        d.estimate, d.goal = r.get("target"), r.get("goal")
        if d.q is not None:
            yield Message("/tf", ns, m.tf(self._arm_transforms(ns, d.q, r.get("pose"))))
            yield Message("/joint_states", ns, m.joint_state(ns, self.names, d.q))
            pressures = self.scene.pressures(d.q)
            yield Message("/pressure_command", ns, m.float_array(pressures, "actuator_psi"))
        for name, camera in self.scene.cameras.items():
            yield Message(f"/{name}/camera_info", ns, m.camera_info(ns, name, camera))
        yield Message("/harvest/markers", ns, scene_markers(m, ns, self.scene, d))
        yield Message("/harvest/state", ns, m.string(str(r.get("state"))))
        yield Message("/diagnostics", ns, self._diagnostics(ns, r))

    def _arm_transforms(self, ns: int, q: FloatArray, measured: Any) -> list[Any]:
        """base -> section_1 -> ... -> section_n (each section's end) at ``q`` on the
        model, and base -> gripper_measured (the cameras' end-effector pose)."""
        frames = np.asarray(self.scene.arm.frames(q)).copy()
        frames[0] = np.eye(4)  # the base frame itself
        names = ["base", *(f"section_{i + 1}" for i in range(len(frames) - 1))]
        out = [
            self.m.transform(ns, names[i], names[i + 1], np.linalg.solve(frames[i], frames[i + 1]))
            for i in range(len(frames) - 1)
        ]
        if measured is not None:
            out.append(self.m.transform(ns, "base", "gripper_measured", measured))
        return out

    def _diagnostics(self, ns: int, r: Mapping[str, Any]) -> Any:
        state = str(r.get("state"))
        level = "ERROR" if state == "fault" else "WARN" if r.get("saturated") else "OK"
        values = [
            (key, _text(r.get(name), scale))
            for key, name, scale in (
                ("berry", "berry", None),
                ("camera", "camera", None),
                ("position_error_mm", "position_error_m", 1e3),
                ("orientation_error_deg", "orientation_error_rad", 180.0 / math.pi),
                ("target_age_s", "target_age_s", 1.0),
                ("saturated", "saturated", None),
            )
        ]
        return self.m.diagnostics(ns, NODE, self.scene.source, level, state, values)

    def _event(self, r: Mapping[str, Any]) -> Iterator[Message]:
        ns, m = self.ns(self.t), self.m
        kind = r["kind"]
        if kind == "transition" and isinstance(r.get("new"), str):
            yield Message("/harvest/state", ns, m.string(r["new"]))
        elif kind == "plan":
            self._plan(r)
        elif kind == "berry_result" and r.get("harvested") and isinstance(r.get("tag_id"), int):
            self.draw.picked.add(r["tag_id"])
            yield Message("/harvest/markers", ns, scene_markers(m, ns, self.scene, self.draw))
        elif kind == "bush_map":
            self._bush_map(r)
            yield Message("/harvest/markers", ns, scene_markers(m, ns, self.scene, self.draw))
        if kind == "bush_map":  # the map is drawn; its line says what it holds
            d = self.draw.detections
            ripe = sum(b.ripe for b in d)
            text = f"bush_map: {len(d)} berries ({ripe} ripe), {len(self.draw.fitted)} canes"
        else:
            fields = {k: v for k, v in r.items() if k not in ("kind", "t", "q")}
            text = f"{kind}: {json.dumps(fields, default=str)}"
        yield Message("/rosout", ns, m.log(ns, _LEVELS.get(kind, "INFO"), NODE, text))

    def _bush_map(self, r: Mapping[str, Any]) -> None:
        """The berries and canes of a ``bush_map`` record become what the markers draw."""
        berries, canes = r.get("berries", []), r.get("canes", [])
        if not isinstance(berries, list) or not isinstance(canes, list):
            raise InputError("bush_map berries and canes must be lists")
        d = self.draw
        d.detections = [_detection(b) for b in berries]
        d.fitted = [_fitted_cane(c) for c in canes]
        d.drawn_ids |= {b.id for b in d.detections}
        d.fitted_slots = max(d.fitted_slots, len(d.fitted))

    def _plan(self, r: Mapping[str, Any]) -> None:
        qs = r.get("q")
        if not isinstance(qs, list):
            raise InputError(f"plan q must be a list of configurations, got {qs!r:.60}")
        arm = self.scene.arm
        tips = [arm.forward(as_vector(q, "plan q", arm.n_actuators))[:3, 3] for q in qs]
        self.draw.plan = np.asarray(tips, dtype=np.float64).reshape(-1, 3)


def _detection(value: Any) -> Detection:
    if not isinstance(value, Mapping) or not isinstance(value.get("id"), int):
        raise InputError(f"bush_map berries: each needs an integer id, got {value!r:.60}")
    radius = _radius(value.get("radius_m"), "bush_map berry radius_m")
    ripe = value.get("ripe")
    if not isinstance(ripe, bool):
        raise InputError(f"bush_map berry ripe must be true or false, got {ripe!r}")
    position = as_vector(value.get("position"), "bush_map berry position", 3)
    return Detection(value["id"], position, radius, ripe)


def _fitted_cane(value: Any) -> tuple[FloatArray, float]:
    if not isinstance(value, Mapping):
        raise InputError(f"bush_map canes: each must be an object, got {value!r:.60}")
    branch = cane_branch(value.get("coeffs"), "bush_map canes")
    return branch.points(CANE_SAMPLES), _radius(value.get("radius_m"), "bush_map cane radius_m")


def _radius(value: Any, name: str) -> float:
    number = isinstance(value, int | float) and not isinstance(value, bool)
    if not number or not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a positive number of metres, got {value!r}")
    return float(value)


def _text(value: Any, scale: float | None) -> str:
    """A diagnostic value as text (numbers scaled to the key's unit, absent ones empty)."""
    if value is None:
        return ""
    if scale is not None and isinstance(value, int | float) and not isinstance(value, bool):
        return f"{scale * value:.6g}"
    return str(value)
