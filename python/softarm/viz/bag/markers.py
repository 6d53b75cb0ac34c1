"""The harvest drawn as a visualization_msgs/MarkerArray in the base frame: the model arm's
backbone (one line strip per section, the rigid links grey), the canes, the berries
coloured by ripeness (picked ones removed), the berry estimate, the servo's goal and the
planned tip path; and, once the markerless harvest has logged a ``bush_map``, what
perception found: each detected berry a translucent sphere of its radius coloured by its
perceived ripeness (``detections``), each fitted cane a translucent line strip as wide
as the cane (``fitted_canes``)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from softarm.viz.arm import arm_polylines
from softarm.viz.bag.messages import Messages

__all__ = ["berry_colour", "perceived_markers", "scene_markers"]

FRAME = "base"
#: Section colours (RGBA 0..1): proximal red, medial green, distal blue, as in the paper.
SECTIONS = ((0.84, 0.15, 0.16, 1.0), (0.17, 0.63, 0.17, 1.0), (0.12, 0.47, 0.71, 1.0))
LINK = (0.45, 0.45, 0.45, 1.0)
CANE = (0.45, 0.3, 0.15, 1.0)
ESTIMATE = (1.0, 0.0, 1.0, 0.9)
GOAL = (1.0, 0.8, 0.0, 1.0)
#: A berry's colour from unripe (green) to ripe (blackberry purple-black).
UNRIPE, RIPE = np.array([0.2, 0.7, 0.2, 1.0]), np.array([0.3, 0.05, 0.35, 1.0])
#: The opacity of what perception found, so the true berries and canes show through.
PERCEIVED_ALPHA = 0.4
FITTED_CANE = (1.0, 0.55, 0.1, PERCEIVED_ALPHA)


def berry_colour(ripeness: float) -> tuple[float, ...]:
    """RGBA of a berry of ``ripeness`` in [0, 1] (clipped)."""
    r = float(np.clip(ripeness, 0.0, 1.0))
    return tuple(float(v) for v in (1.0 - r) * UNRIPE + r * RIPE)


def scene_markers(m: Messages, ns: int, scene: Any, state: Any) -> Any:
    """The MarkerArray at time ``ns``: ``scene`` (a :class:`~softarm.viz.bag.scene.RunScene`)
    and ``state`` (the converter's ``DrawState``: q, estimate, goal, plan, picked tags)."""
    out: list[Any] = []
    if state.q is not None:
        arcs, links = arm_polylines(scene.arm, state.q, 20)
        for i, arc in enumerate(arcs):
            out.append(_strip(m, ns, "backbone", i, arc, SECTIONS[i % len(SECTIONS)], 0.012))
        for j, link in enumerate(links):
            out.append(_strip(m, ns, "links", j, link, LINK, 0.008))
    for i, cane in enumerate(scene.canes):
        out.append(_strip(m, ns, "canes", i, cane, CANE, 0.008))
    on_bush = [b for b in scene.berries if b.tag_id not in state.picked]
    out.append(
        _spheres(m, ns, "berries", 0, [b.position for b in on_bush],
                 [berry_colour(b.ripeness) for b in on_bush], 0.02)
    )  # fmt: skip
    for name, point, colour, size in (
        ("estimate", state.estimate, ESTIMATE, 0.012),
        ("goal", state.goal, GOAL, 0.008),
    ):
        pts = [] if point is None else [point]
        out.append(_spheres(m, ns, name, 0, pts, [colour] * len(pts), size))
    out.append(_strip(m, ns, "plan", 0, state.plan, GOAL, 0.004))
    out += perceived_markers(m, ns, state)
    return m.new("visualization_msgs/msg/MarkerArray", markers=out)


def perceived_markers(m: Messages, ns: int, state: Any) -> list[Any]:
    """The latest bush map's berries (one sphere each, its id the berry's) and fitted
    canes; one a former map drew (``state.drawn_ids``, ``state.fitted_slots``) and this
    one lacks is sent as DELETE. Nothing before the first map."""
    out: list[Any] = []
    current = {d.id: d for d in state.detections}
    for berry_id in sorted(state.drawn_ids | set(current)):
        d = current.get(berry_id)
        if d is None:
            out.append(_marker(m, ns, "detections", berry_id, "SPHERE", np.zeros((0, 3)), [],
                               (0.0, 0.0, 0.0)))  # fmt: skip
            continue
        colour = (*berry_colour(1.0 if d.ripe else 0.0)[:3], PERCEIVED_ALPHA)
        size = 2.0 * d.radius
        out.append(_marker(m, ns, "detections", berry_id, "SPHERE", np.zeros((0, 3)), [colour],
                           (size, size, size), position=d.position))  # fmt: skip
    for i in range(max(state.fitted_slots, len(state.fitted))):
        points, radius = state.fitted[i] if i < len(state.fitted) else (np.zeros((0, 3)), 0.0)
        out.append(_strip(m, ns, "fitted_canes", i, points, FITTED_CANE, 2.0 * radius))
    return out


def _strip(
    m: Messages, ns: int, name: str, i: int, points: Any, colour: Sequence[float], width: float
) -> Any:
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return _marker(m, ns, name, i, "LINE_STRIP", pts, [colour] * len(pts), (width, 0.0, 0.0))


def _spheres(
    m: Messages, ns: int, name: str, i: int, points: Sequence[Any],
    colours: Sequence[Sequence[float]], size: float,
) -> Any:  # fmt: skip
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return _marker(m, ns, name, i, "SPHERE_LIST", pts, colours, (size, size, size))


def _marker(
    m: Messages, ns: int, name: str, i: int, kind: str, points: np.ndarray,
    colours: Sequence[Sequence[float]], scale: tuple[float, float, float],
    position: Any = None,
) -> Any:  # fmt: skip
    """One marker (a single shape at ``position``, or a list of ``points``); one with
    neither is sent as DELETE, so the viewer clears what it drew."""
    Marker = m.types["visualization_msgs/msg/Marker"]
    action = Marker.ADD if len(points) or position is not None else Marker.DELETE
    pose = np.eye(4)
    if position is not None:
        pose[:3, 3] = position
    return Marker(
        header=m.header(ns, FRAME),
        ns=name,
        id=i,
        type=getattr(Marker, kind),
        action=action,
        pose=m.pose(pose),
        scale=m.vector(scale),
        color=m.color(colours[0] if len(colours) else (1.0, 1.0, 1.0, 1.0)),
        lifetime=m.new("builtin_interfaces/msg/Duration", sec=0, nanosec=0),
        frame_locked=False,
        points=[m.point(p) for p in points],
        colors=[m.color(c) for c in colours],
        texture_resource="",
        texture=m.new(
            "sensor_msgs/msg/CompressedImage",
            header=m.header(ns, ""),
            format="",
            data=np.zeros(0, dtype=np.uint8),
        ),
        uv_coordinates=[],
        text="",
        mesh_resource="",
        mesh_file=m.new(
            "visualization_msgs/msg/MeshFile", filename="", data=np.zeros(0, dtype=np.uint8)
        ),
        mesh_use_embedded_materials=False,
    )
