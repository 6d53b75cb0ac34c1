"""Where the arm touches the true canes in a simulated markerless harvest, and why the
map let it: the harvest of ``softarm harvest --sim --world row|bush`` run with a watch on
every contact step (the true arm's surface gap to a true cane below zero).

Each run of contact steps on one cane in one stage is an *episode*: the cane, the arm's
piece nearest it (a section or the gripper), the point touched (its distance from the
base, whether it lies in C1's field of view), what the planner's map held there (the
nearest fitted curve to that point), the model's gap at the commanded elongations to the
map and to the true canes, and a cause:

- ``beyond reach``: the point lies farther than ``CANE_REACH`` from the base, where the
  map leaves canes out;
- ``not seen``: within reach, no fitted curve within ``MAPPED_MM`` of the point;
- ``mapped``: a fitted curve lies there; the model arm kept clear of it (or not), the true
  arm did not (tracking, the model's shape, or the planner's margin).

Beside the cause: the nearest of C1's own curves (the planner's fallback after C2's
survey), the model's gap to the map at the true shape, how far the true grasp point is
from the model's at the command (the plant's lag and the model's error; the latter alone:
the model's grasp point at the true shape), and the share of the touched cane the
map and C1's own curves hold within ``MAPPED_MM``.

    python -m softarm.experiments.row_contacts SEED LOOK [--berries N] [--world row|bush]
        [--out trace.json] [--report report.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.harvest.control.clearance import CANE_RADIUS, Clearance
from softarm.harvest.rigs.sim import devices
from softarm.perception.self_filter import CANE_REACH
from softarm.sim.world import WorldName

__all__ = ["Episode", "Step", "cause_of", "episodes", "main", "trace"]

#: A fitted curve within this distance (mm) of the point touched counts as mapping it.
MAPPED_MM = 10.0

#: The unripe share of the rendered worlds' berries, as ``softarm harvest --sim`` draws
#: them (``commands.harvest.BUSH_UNRIPE_FRACTION``; the experiments sit below commands).
UNRIPE_FRACTION = 0.3

#: Samples along a cane and along the arm when looking for the point touched.
CANE_SAMPLES = 400
ARM_SAMPLES = 60


@dataclass
class Step:
    """One contact step: what the true arm touched and what the planner knew there."""

    t: float
    state: str
    berry: int | None
    gap_mm: float
    cane: int
    piece: str
    point: list[float]
    from_base_m: float
    in_c1_view: bool
    map_mm: float  # nearest fitted curve of the planner's map to the point
    model_map_gap_mm: float  # the model arm at the command, to the map
    model_true_gap_mm: float  # the model arm at the command, to the true canes
    fell_back: bool
    c1_mm: float = float("inf")  # nearest of C1's own curves (the fallback) to the point
    model_map_gap_true_q_mm: float = float("inf")  # the model at the TRUE shape, to the map
    lag_mm: float = 0.0  # the true grasp point from the model's at the command
    cane_covered: float = 0.0  # share of the touched cane within MAPPED_MM of the map
    cane_covered_c1: float = 0.0  # the same of C1's own curves
    shape_mm: float = 0.0  # the model's grasp point at the TRUE shape from the true one


@dataclass
class Episode:
    """Consecutive contact steps on one cane in one stage of one berry."""

    cane: int
    state: str
    berry: int | None
    steps: int
    t0: float
    t1: float
    min_gap_mm: float
    pieces: list[str]
    from_base_m: float
    in_c1_view: bool
    map_mm: float
    model_map_gap_mm: float
    model_true_gap_mm: float
    fell_back: bool
    cause: str = ""
    c1_mm: float = float("inf")
    model_map_gap_true_q_mm: float = float("inf")
    lag_mm: float = 0.0
    cane_covered: float = 0.0
    cane_covered_c1: float = 0.0
    shape_mm: float = 0.0
    transitions: list[str] = field(default_factory=list)


def cause_of(from_base_m: float, map_mm: float) -> str:
    """Why the map let the arm touch a cane at a point ``from_base_m`` from the base whose
    nearest fitted curve is ``map_mm`` away (see the module's list)."""
    if from_base_m > CANE_REACH:
        return "beyond reach"
    if not map_mm <= MAPPED_MM:  # inf (an empty map) or NaN too
        return "not seen"
    return "mapped"


def episodes(steps: Sequence[Step], dt_max: float = 0.05) -> list[Episode]:
    """Group ``steps`` into episodes: the same cane, stage and berry, each step within
    ``dt_max`` s of the one before. The episode's figures are its deepest step's."""
    out: list[Episode] = []
    group: list[Step] = []
    for s in steps:
        if group and not _same(group[-1], s, dt_max):
            out.append(_episode(group))
            group = []
        group.append(s)
    if group:
        out.append(_episode(group))
    return out


def _same(a: Step, b: Step, dt_max: float) -> bool:
    return (a.cane, a.state, a.berry) == (b.cane, b.state, b.berry) and b.t - a.t <= dt_max


def _episode(group: list[Step]) -> Episode:
    deep = min(group, key=lambda s: s.gap_mm)
    return Episode(
        deep.cane, deep.state, deep.berry, len(group), group[0].t, group[-1].t, deep.gap_mm,
        sorted({s.piece for s in group}), deep.from_base_m, deep.in_c1_view, deep.map_mm,
        deep.model_map_gap_mm, deep.model_true_gap_mm, deep.fell_back,
        cause_of(deep.from_base_m, deep.map_mm), deep.c1_mm, deep.model_map_gap_true_q_mm,
        deep.lag_mm, deep.cane_covered, deep.cane_covered_c1, deep.shape_mm,
    )  # fmt: skip


def touched_point(
    backbone: FloatArray, gripper: FloatArray, cane_points: FloatArray, sections: int
) -> tuple[FloatArray, str]:
    """The cane point nearest the arm (``backbone`` (N, 3) points evenly along the
    sections, ``gripper`` (M, 3) along the gripper's capsule) and the arm's piece there:
    ``section K`` (from the base, 0 first) or ``gripper``."""
    arm = np.vstack([backbone, gripper])
    d = np.linalg.norm(arm[:, None, :] - cane_points[None, :, :], axis=2)
    i, j = np.unravel_index(int(np.argmin(d)), d.shape)
    if i >= len(backbone):
        return cane_points[j], "gripper"
    return cane_points[j], f"section {min(int(i * sections / len(backbone)), sections - 1)}"


def covered(cane: Any, curves: Sequence[Any]) -> float:
    """The share of ``cane``'s samples within ``MAPPED_MM`` of one of ``curves``."""
    if not curves:
        return 0.0
    pts = np.vstack([np.asarray(c.sample(CANE_SAMPLES)) for c in curves])
    near = [np.min(np.linalg.norm(pts - p, axis=1)) for p in np.asarray(cane.sample(100))]
    return float(np.mean(np.array(near) <= MAPPED_MM / 1e3))


def nearest_mm(point: FloatArray, curves: Sequence[Any]) -> float:
    """Distance (mm) from ``point`` to the nearest of ``curves`` (sampled); inf without."""
    if not curves:
        return float("inf")
    pts = np.vstack([np.asarray(c.sample(CANE_SAMPLES)) for c in curves])
    return float(1e3 * np.min(np.linalg.norm(pts - point, axis=1)))


class _Tracer:
    """The hook on the true arm's watch: every contact step recorded as a :class:`Step`."""

    def __init__(self) -> None:
        self.rig: Any = None
        self.steps: list[Step] = []
        self.berry: int | None = None
        self.transitions: list[tuple[float, str, int | None, str]] = []

    def on_sample(self, watch: devices.ArmWatch) -> None:
        if self.rig is None:  # the rig is still being built
            return
        q = watch.plant.q()
        true = watch.clearance
        gaps = [true.body.gap(true.arm, q, [c], CANE_RADIUS) for c in true.canes]
        if not gaps or min(gaps) >= 0.0:
            return
        self.steps.append(self._step(q, true, int(np.argmin(gaps)), min(gaps)))

    def _step(self, q: FloatArray, true: Clearance, cane: int, gap: float) -> Step:
        rig, machine = self.rig, self.rig.machine
        pose = true.arm.forward(q)
        tip = pose[:3, 3]
        grip = tip[None, :] + np.linspace(0, true.offset, 8)[:, None] * pose[:3, 2][None, :]
        backbone = np.asarray(true.arm.backbone(q, ARM_SAMPLES))
        point, piece = touched_point(backbone, grip, true.canes[cane].sample(CANE_SAMPLES),
                                     true.arm.n_sections)  # fmt: skip
        planner = machine.planner
        mapped = planner.clearance.canes if planner is not None and planner.clearance else []
        own = planner.fallback.canes if planner is not None and planner.fallback else mapped
        model, cmd = rig.model, machine.q
        on_map = Clearance(model, mapped, true.offset)
        model_true = Clearance(model, true.canes, true.offset).gap(cmd)
        at = _grasp(true.arm, q, true.offset)
        lag = np.linalg.norm(_grasp(model, cmd, true.offset) - at)
        shape = np.linalg.norm(_grasp(model, q, true.offset) - at)
        return Step(
            rig.clock.now(), str(machine.state), self.berry, 1e3 * gap, cane, piece,
            [float(x) for x in point], float(np.linalg.norm(point)), self._in_c1(point),
            nearest_mm(point, mapped), 1e3 * on_map.gap(cmd), 1e3 * model_true,
            bool(planner is not None and planner.fell_back), nearest_mm(point, own),
            1e3 * on_map.gap(q), 1e3 * float(lag), covered(true.canes[cane], mapped),
            covered(true.canes[cane], own), 1e3 * float(shape),
        )  # fmt: skip

    def _in_c1(self, point: FloatArray) -> bool:
        """Whether ``point`` (base frame) falls inside C1's left image (occlusion aside)."""
        scene = self.rig.scene
        if scene is None:
            return True
        c1 = scene.c1()
        p = np.linalg.inv(c1.T_base_left) @ np.append(point, 1.0)
        if p[2] <= 0:
            return False
        u, v = np.asarray(c1.left.project(p[None, :3])).reshape(-1)[:2]
        w, h = c1.left.image_size or (0, 0)
        return bool(0 <= u < w and 0 <= v < h)


def _grasp(arm: Any, q: FloatArray, offset: float) -> FloatArray:
    """The grasp point of ``arm`` at ``q``: ``offset`` ahead of the end effector."""
    pose = np.asarray(arm.forward(q))
    return np.asarray(pose[:3, 3] + offset * pose[:3, 2])


@contextmanager
def _watched(tracer: _Tracer) -> Iterator[None]:
    """``ArmWatch.sample`` calls the tracer after each sample, for this block only."""
    original = devices.ArmWatch.sample

    def sample(self: devices.ArmWatch, dt: float = 0.0) -> None:
        original(self, dt)
        tracer.on_sample(self)

    devices.ArmWatch.sample = sample  # type: ignore[method-assign]
    try:
        yield
    finally:
        devices.ArmWatch.sample = original  # type: ignore[method-assign]


def trace(
    seed: int, look: str | None, berries: int = 4, world: WorldName = WorldName.ROW,
    report: Path | None = None,
) -> dict[str, Any]:  # fmt: skip
    """Harvest ``seed`` as ``softarm harvest --sim --world WORLD --look LOOK --berries N``
    does, the contact steps traced; the report saved to ``report`` where given. Returns
    the episodes, the map's canes count and the report's headline figures."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    options = SimRigOptions(
        n_berries=berries, seed=seed, world=world, unripe_fraction=UNRIPE_FRACTION,
        look=look if world is WorldName.ROW else None,
    )  # fmt: skip
    tracer = _Tracer()
    with _watched(tracer):
        rig = build_sim_rig(options)
        try:
            tracer.rig = rig
            _follow_transitions(rig.machine, tracer)
            done = rig.run()
        finally:
            rig.close()
    if report is not None:
        done.save(report)
    result = done.to_dict()
    return _summary(tracer, rig, result)


def _follow_transitions(machine: Any, tracer: _Tracer) -> None:
    """Keep the tracer told of the berry the machine works on and its stage changes."""
    original = machine._transition

    def transition(new: Any, berry: Any, reason: str) -> None:
        tracer.berry = int(berry.tag_id)
        tracer.transitions.append((machine.clock.now(), str(new), tracer.berry, reason))
        original(new, berry, reason)

    machine._transition = transition


def _summary(tracer: _Tracer, rig: Any, result: dict[str, Any]) -> dict[str, Any]:
    found = episodes(tracer.steps)
    for e in found:  # the stage changes around each episode: what the machine was doing
        e.transitions = [
            f"{t:.2f} s {state} berry {b}: {why}"
            for t, state, b, why in tracer.transitions
            if b == e.berry and e.t0 - 3.0 <= t <= e.t1 + 1.0
        ]
    keys = ("ripe_in_reach", "ripe_harvested", "unripe_picked", "branch_contact_steps",
            "min_branch_gap_m", "cane_map")  # fmt: skip
    return {
        "contact_steps": len(tracer.steps),
        "episodes": [asdict(e) for e in found],
        "true_canes": len(rig.watch.clearance.canes),
        "report": {k: result.get(k) for k in keys},
    }


def _plain(x: Any) -> Any:
    """JSON for numpy values in the report."""
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    return str(x)


def main(argv: list[str] | None = None) -> int:
    """``SEED LOOK [--berries N] [--world row|bush] [--out FILE] [--report FILE]``: trace
    one harvest; the trace printed, and written to ``--out``."""
    p = argparse.ArgumentParser(prog="row_contacts", description=main.__doc__)
    p.add_argument("seed", type=int)
    p.add_argument("look", help="the row's look, or - for the world's default")
    p.add_argument("--berries", type=int, default=4)
    p.add_argument("--world", choices=[w.value for w in WorldName], default="row")
    p.add_argument("--out", type=Path, help="also write the trace (JSON) to this file")
    p.add_argument("--report", type=Path, help="write the harvest's report to this file")
    args = p.parse_args(argv)
    look = None if args.look == "-" else args.look
    out = trace(args.seed, look, args.berries, WorldName(args.world), args.report)
    text = json.dumps(out, indent=1, default=_plain)
    if args.out is not None:
        args.out.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
