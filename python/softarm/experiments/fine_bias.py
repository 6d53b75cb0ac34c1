"""Where fine positioning's measurement bias in the rendered bush comes from (issue 40,
item 2): the true grasp error left once the measured one is within ``fine_tolerance``.

Close to the berry the berry is where C2's ray through the fruit's image centre passes
nearest C1's ray to it (:class:`~softarm.perception.approach.RayCrossing`), carried into
the end-effector frame through the cube's pose (eq. 21-22). Three measured inputs make
that point, each with a true counterpart in the simulation:

- ``c1_ray``: C1's ray, through the map's berry (C1's stereo), against the ray through
  the true berry centre;
- ``c2_centre``: C2's ray, through the detection's centre, against the ray through the
  true centre (from C2's true pose);
- ``cube``: C2's pose in C1's frame from the tracked cube, against the true one (the
  hand-eye pose is exact in the simulation, so C2's pose error is the cube's; C1's base
  registration cancels: both rays are in C1's frame).

For every C2 fix during a harvest the berry is recomputed in the end-effector frame with
the measured inputs, with each one at a time replaced by its truth, and with all three
(which gives the true berry exactly). At each grasp the mean over the last
:data:`WINDOW` fixes gives the bias (true minus measured berry) and each source's share:
the bias left when that source alone is made true.

    MUJOCO_GL=egl python -m softarm.experiments.fine_bias --seeds 1250 1251 --berries 8 \
        --out out/fine_bias.jsonl
    python -m softarm.experiments.fine_bias --summary out/fine_bias.jsonl

It lives above :mod:`softarm.perception` (which may not import the simulation).
"""

from __future__ import annotations

import argparse
import itertools
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from softarm.checks import FloatArray

__all__ = ["SOURCES", "BiasTrace", "cross_rays", "summarise"]

#: The measured inputs substituted one at a time (see the module docstring).
SOURCES = ("c1_ray", "c2_centre", "cube")
#: The last C2 fixes before a grasp averaged into its bias (the confidence rule's window).
WINDOW = 10
#: Fine positioning's budget (s): a berry longer than this ran it out.
FINE_BUDGET_S = 12.0


def cross_rays(
    c1_dir: FloatArray,
    c2_ray: FloatArray,
    T_c1_c2: FloatArray,
    c1_origin: FloatArray | None = None,
    spreads: tuple[float, float] | None = None,
) -> FloatArray | None:
    """The point on C2's ray (unit ``c2_ray`` in C2's frame) nearest C1's ray (unit
    ``c1_dir`` from ``c1_origin``, C1's origin when None, C1's frame), in C2's frame;
    with ``spreads`` (each ray's, rad) moved towards C1's ray's nearest point by the
    share the two spreads give it; None when the two are parallel.
    :meth:`RayCrossing.fix` in C1's frame."""
    ray = T_c1_c2[:3, :3] @ c2_ray
    start = np.zeros(3) if c1_origin is None else c1_origin
    origin = T_c1_c2[:3, 3] - start
    b = float(c1_dir @ ray)
    if 1.0 - b * b < 1e-9:
        return None
    t = (b * float(c1_dir @ origin) - float(ray @ origin)) / (1.0 - b * b)
    result: FloatArray = c2_ray * t
    if spreads is not None:
        s = (float(c1_dir @ origin) - b * float(ray @ origin)) / (1.0 - b * b)
        on_c1 = T_c1_c2[:3, :3].T @ (start + s * c1_dir - T_c1_c2[:3, 3])
        var1, var2 = (spreads[0] * s) ** 2, (spreads[1] * t) ** 2
        result = result + var2 / (var1 + var2) * (on_c1 - result)
    return result


def _unit(v: FloatArray) -> FloatArray:
    out: FloatArray = v / np.linalg.norm(v)
    return out


def _apply(T: Any, p: Any) -> FloatArray:
    out: FloatArray = np.asarray(T[:3, :3] @ p + T[:3, 3], dtype=np.float64)
    return out


@dataclass
class Fix:
    """One C2 fix: the berry in the end-effector frame (m) from the measured inputs
    (``measured``), with each subset of :data:`SOURCES` true (``by``, keyed by the
    sorted names joined with '+'), and the truth."""

    t: float
    berry: int
    measured: FloatArray
    truth: FloatArray
    by: dict[str, FloatArray]
    c2_centre_px: float  # the detection's centre from the true centre's projection
    c1_ray_px: float = 0.0  # C1's ray from the true one, in C1's pixels


def _cube_parts(poses: dict[str, FloatArray], T_ee_c2: FloatArray) -> dict[str, FloatArray]:
    """C2's pose in C1's frame with the end effector's true rotation and measured
    position (``cube_rotation``: its rotation error taken out), and the other way
    round (``cube_position``)."""
    T_c2_ee = np.linalg.inv(T_ee_c2)
    meas, true = poses["measured"] @ T_c2_ee, poses["true"] @ T_c2_ee
    rot, pos = meas.copy(), meas.copy()
    rot[:3, :3], pos[:3, 3] = true[:3, :3], true[:3, 3]
    return {"cube_rotation": rot @ T_ee_c2, "cube_position": pos @ T_ee_c2}


@dataclass
class BiasTrace:
    """Taps a simulated bush rig's C2 fixes and grasps (see the module docstring)."""

    rig: Any
    fixes: list[Fix] = field(default_factory=list)
    grasps: list[dict[str, Any]] = field(default_factory=list)

    def attach(self) -> None:
        """Wrap the vision's berry selection (to tap each new RayCrossing) and the
        gripper's close (to mark each grasp)."""
        vision, gripper = self.rig.vision, self.rig.gripper
        select, close = vision.select, gripper.close

        def tapped_select(berry: Any) -> None:
            select(berry)
            track = vision._track
            if track is not None:
                fix = track.fix

                def tapped_fix(det: Any, T_base_camera: FloatArray, camera: Any) -> Any:
                    out = fix(det, T_base_camera, camera)
                    if out is not None:
                        self._record(track, det, T_base_camera)
                    return out

                track.fix = tapped_fix

        def tapped_close() -> None:
            self._grasp()
            close()

        vision.select, gripper.close = tapped_select, tapped_close

    def _truths(self) -> tuple[FloatArray, FloatArray, FloatArray | None]:
        """The true C1 pose (base frame), end-effector pose, and selected berry."""
        scene = self.rig.scene
        truth = scene.truth_of(self.rig.vision.selected.tag_id)
        berry = None if truth is None else np.asarray(truth.position, dtype=np.float64)
        return scene.world.stereo.T_base_left, scene.plant.pose(), berry

    def _record(self, track: Any, det: Any, T_base_c2: FloatArray) -> None:
        """The fix of ``det`` recomputed under every subset of true inputs."""
        vision = self.rig.vision
        T_base_c1_true, T_base_ee_true, berry = self._truths()
        if berry is None:
            return
        T_ee_c2 = vision._T_ee_c2
        T_c1_base = np.linalg.inv(vision.T_base_c1)
        T_c1_base_true = np.linalg.inv(T_base_c1_true)
        berry_c1 = _apply(T_c1_base_true, berry)
        poses = {
            "measured": T_c1_base @ T_base_c2,
            "true": T_c1_base_true @ T_base_ee_true @ T_ee_c2,
        }
        x, y = vision.model2.normalize(np.array([det.center]))[0]
        true_c2 = _apply(np.linalg.inv(poses["true"]), berry_c1)
        rays = {"measured": _unit(np.array([x, y, 1.0])), "true": _unit(true_c2)}
        # C1's ray starts where the harvest's does (the baseline's middle), fixed in C1.
        o1 = _apply(T_c1_base, track.c1_centre)
        c1 = {
            "measured": _unit(_apply(T_c1_base, track.position) - o1),
            "true": _unit(berry_c1 - o1),
        }
        projected = vision.model2.project(true_c2[None, :])[0]
        # The harvest's weighing of the two rays (RayCrossing.spreads), C2's in rad.
        w = (
            None
            if track.spreads is None
            else (track.spreads[0], track.spreads[1] / vision.model2.focal)
        )
        by: dict[str, FloatArray] = {}
        for k in range(len(SOURCES) + 1):
            for subset in itertools.combinations(SOURCES, k):
                pick = {s: "true" if s in subset else "measured" for s in SOURCES}
                p = cross_rays(
                    c1[pick["c1_ray"]], rays[pick["c2_centre"]], poses[pick["cube"]], o1, w
                )
                if p is None:
                    return
                by["+".join(subset)] = _apply(T_ee_c2, p)
        for part, mixed in _cube_parts(poses, T_ee_c2).items():  # the cube's two errors
            p = cross_rays(c1["measured"], rays["measured"], mixed, o1, w)
            if p is None:
                return
            by[part] = _apply(T_ee_c2, p)
        truth = _apply(np.linalg.inv(T_base_ee_true), berry)
        offset = float(np.hypot(*(np.asarray(det.center) - projected)))
        angle = float(np.arccos(np.clip(c1["measured"] @ c1["true"], -1.0, 1.0)))
        c1_px = angle * float(self.rig.scene.world.stereo.rectification.focal)
        self.fixes.append(
            Fix(self.rig.clock.now(), vision.selected.tag_id, by[""], truth, by, offset, c1_px)
        )

    def _grasp(self) -> None:
        """A grasp of the selected berry: its true grasp error and its last fixes."""
        _, T_base_ee_true, berry = self._truths()
        tag = self.rig.vision.selected.tag_id
        since = self.grasps[-1]["fixes_to"] if self.grasps else 0
        recent = [f for f in self.fixes[since:] if f.berry == tag][-WINDOW:]
        grasp = np.array([0.0, 0.0, self.rig.machine.config.grasp_offset])
        true = None if berry is None else _apply(np.linalg.inv(T_base_ee_true), berry) - grasp
        self.grasps.append(
            {
                "berry": tag,
                "fixes_to": len(self.fixes),
                "true_error": true,
                "recent": recent,
                "grasp_point": grasp,
            }
        )


def decompose(grasp: dict[str, Any]) -> dict[str, Any] | None:
    """One grasp's bias (true minus measured berry, end-effector frame, mm; its norm and
    its component along the approach axis z) and, per source, the bias left with that
    source alone true; None without fixes or truth."""
    recent: list[Fix] = grasp["recent"]
    if not recent or grasp["true_error"] is None:
        return None
    measured = np.mean([f.measured for f in recent], axis=0)
    truth = np.mean([f.truth for f in recent], axis=0)
    bias = 1e3 * (truth - measured)
    left = {}
    for s in (*SOURCES, "cube_rotation", "cube_position"):
        sub = np.mean([f.by[s] for f in recent], axis=0)
        left[s] = _mm(1e3 * (truth - sub))
    # Every source true but one: what that one alone carries.
    alone = {}
    for s in SOURCES:
        others = "+".join(x for x in SOURCES if x != s)
        sub = np.mean([f.by[others] for f in recent], axis=0)
        alone[s] = _mm(1e3 * (truth - sub))
    return {
        "berry": grasp["berry"],
        "true_mm": float(1e3 * np.linalg.norm(grasp["true_error"])),
        "true_vec_mm": [round(float(v), 3) for v in 1e3 * grasp["true_error"]],
        "last_measured_mm": _mm(1e3 * (recent[-1].measured - grasp["grasp_point"])),
        "bias": _mm(bias),
        "left_when_true": left,
        "carried_alone": alone,
        "c2_centre_px": float(np.median([f.c2_centre_px for f in recent])),
        "c1_ray_px": float(np.median([f.c1_ray_px for f in recent])),
        "fixes": len(recent),
    }


def _mm(v: FloatArray) -> dict[str, Any]:
    return {
        "norm": round(float(np.linalg.norm(v)), 3),
        "axial": round(float(v[2]), 3),
        "lateral": round(float(np.hypot(v[0], v[1])), 3),
        "vec": [round(float(x), 3) for x in v],
    }


def run_seed(
    seed: int, berries: int, body: str, rule: str, label: str, fine_aim: float = 0.0
) -> dict[str, Any]:
    """One traced harvest of the rendered bush under the fine end ``rule`` (and
    ``fine_aim``, m) with the marker ``body``: its report's figures and each grasp's
    decomposition, tagged ``label`` (the code measured: before or after a change)."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.harvest_config import HarvestConfig
    from softarm.sim.world import WorldName

    options = SimRigOptions(
        n_berries=berries, seed=seed, world=WorldName.BUSH,
        config=HarvestConfig(fine_end_rule=rule, fine_aim=fine_aim), marker_body=body,
    )  # fmt: skip
    rig = build_sim_rig(options)
    trace = BiasTrace(rig)
    trace.attach()
    try:
        report = rig.run().to_dict()
    finally:
        rig.close()
    grasps = [d for g in trace.grasps if (d := decompose(g)) is not None]
    return {"label": label, "seed": seed, "body": body, "rule": rule, "grasps": grasps,
            **_figures(report)}  # fmt: skip


def _figures(report: dict[str, Any]) -> dict[str, Any]:
    """What the measurement table needs of a harvest's report."""
    tried = [b for b in report["berries"] if not b["skipped_unripe"] and b.get("ripe") is not False]
    done = [b for b in tried if b["harvested"]]
    return {
        "ripe": report.get("ripe_in_reach", report["attempted"]),
        "harvested": report["rate"]["harvested"],
        "unripe_picked": report.get("unripe_picked", 0),
        "contact_steps": report["branch_contact_steps"],
        "total_s": report["rate"]["total_s"],
        "survey_s": report["rate"]["stage_s"]["survey"],
        "berry_s": [b["duration_s"] for b in done],
        "true_mm": [b["true_position_error_mm"] for b in done],
        "measured_mm": [b["position_error_mm"] for b in done],
        "over_budget": sum(b["duration_s"] > FINE_BUDGET_S for b in tried),
    }


def table(rows: list[dict[str, Any]]) -> str:
    """A markdown table of ``rows``: one line per code label, end rule and body."""
    out = [
        "| code | rule | body | bushes | s/berry mean | s/berry p90 | true mm median | true mm p95 "
        "| true > 0.5 mm | harvested | unripe | contacts | berries > 12 s |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    keys = sorted({(r["label"], r["rule"], r["body"]) for r in rows})
    for key in keys:
        group = [r for r in rows if (r["label"], r["rule"], r["body"]) == key]
        f = pooled(group)
        out.append(
            f"| {key[0]} | {key[1]} | {key[2]} | {len(group)} | {f['s_per_berry']:.2f} | "
            f"{f['s_per_berry_p90']:.2f} | {f['true_median_mm']:.2f} | {f['true_p95_mm']:.2f} | "
            f"{f['true_over_05']}/{f['true_n']} | {f['harvested']}/{f['ripe']} | "
            f"{f['unripe_picked']} | {f['contact_steps']} | {f['over_budget']} |"
        )
    return "\n".join(out)


def pooled(group: list[dict[str, Any]]) -> dict[str, Any]:
    """The figures of one group of bushes: simulated seconds per berry harvested (survey
    and way home included) and its 90th percentile (each berry's own time plus its
    share of its bush's survey), the true fine error, the counts."""
    harvested = sum(r["harvested"] for r in group)
    per_berry = [s + r["survey_s"] / max(r["harvested"], 1) for r in group for s in r["berry_s"]]
    true = np.array([e for r in group for e in r["true_mm"]], dtype=float)
    return {
        "s_per_berry": sum(r["total_s"] for r in group) / max(harvested, 1),
        "s_per_berry_p90": float(np.percentile(per_berry, 90)) if per_berry else float("nan"),
        "true_median_mm": float(np.median(true)) if true.size else float("nan"),
        "true_p95_mm": float(np.percentile(true, 95)) if true.size else float("nan"),
        "true_over_05": int(np.sum(true > 0.5)),
        "true_n": int(true.size),
        "harvested": harvested,
        "ripe": sum(r["ripe"] for r in group),
        "unripe_picked": sum(r["unripe_picked"] for r in group),
        "contact_steps": sum(r["contact_steps"] for r in group),
        "over_budget": sum(r["over_budget"] for r in group),
    }


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The decomposition pooled over every grasp of ``rows``: how many grasps end with
    a true error within 0.5 mm as measured, and as they would with no bias or with
    each source alone made true (the grasp's residual, true minus bias, kept); the
    median bias and, per source, the median bias it carries alone. ``without_residual``:
    as they would had fine positioning ended on the measured berry itself (the end
    rule's residual 0, the bias alone; per source, with that source also true)."""
    grasps = [g for r in rows for g in r["grasps"]]
    if not grasps:
        return {"grasps": 0}
    true = np.array([g["true_vec_mm"] for g in grasps])
    bias = np.array([g["bias"]["vec"] for g in grasps])
    residual = true - bias

    def within(v: FloatArray) -> int:
        return int(np.sum(np.linalg.norm(v, axis=1) <= 0.5))

    out: dict[str, Any] = {
        "grasps": len(grasps),
        "seeds": sorted({r["seed"] for r in rows}),
        "true_within_0.5mm": within(true),
        "without_bias": within(residual),
        # Fine positioning ended on the measured berry itself: the true error is the bias.
        "without_residual": within(bias),
        "residual_norm_median_mm": _median(np.linalg.norm(residual, axis=1)),
        "bias_norm_median_mm": _median(np.linalg.norm(bias, axis=1)),
        "c1_ray_px_median": _median([g.get("c1_ray_px", np.nan) for g in grasps]),
        "bias_axial_rms_mm": round(float(np.sqrt(np.mean(bias[:, 2] ** 2))), 3),
        "bias_lateral_rms_mm": round(float(np.sqrt(np.mean(np.sum(bias[:, :2] ** 2, 1)))), 3),
    }
    for s in (*SOURCES, "cube_rotation", "cube_position"):
        if s not in grasps[0]["left_when_true"]:
            continue
        left = np.array([g["left_when_true"][s]["vec"] for g in grasps])
        out[s] = {
            "within_0.5mm_when_true": within(residual + left),
            "within_0.5mm_when_true_without_residual": within(left),
        }
        if s in SOURCES:
            alone = np.array([g["carried_alone"][s]["vec"] for g in grasps])
            out[s]["alone_norm_median_mm"] = _median(np.linalg.norm(alone, axis=1))
            out[s]["alone_rms_mm"] = round(float(np.sqrt(np.mean(np.sum(alone**2, 1)))), 3)
    return out


def by_group(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per code label, end rule and body: the seeds, the table's figures
    (:func:`pooled`) and the decomposition (:func:`summarise`)."""
    out = []
    for key in sorted({(r["label"], r["rule"], r["body"]) for r in rows}):
        group = [r for r in rows if (r["label"], r["rule"], r["body"]) == key]
        out.append(
            {
                "code": key[0],
                "rule": key[1],
                "body": key[2],
                "seeds": sorted({r["seed"] for r in group}),
                "figures": pooled(group),
                "decomposition": summarise(group),
            }
        )
    return out


def _median(values: Any) -> float:
    return round(float(np.median(np.asarray(values, dtype=float))), 3)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1250])
    parser.add_argument("--berries", type=int, default=8)
    parser.add_argument("--marker-body", choices=("cube", "frustum"), default="cube")
    parser.add_argument("--rules", choices=("steps", "confidence"), nargs="+", default=["steps"])
    parser.add_argument("--fine-aim", type=float, default=0.0, help="[harvest] fine_aim (m)")
    parser.add_argument("--label", default="now", help="the code measured (before, after)")
    parser.add_argument("--out", type=Path, default=Path("out/fine_bias.jsonl"))
    parser.add_argument("--summary", type=Path, nargs="+", help="summarise these")
    parser.add_argument("--json", type=Path, help="with --summary: write the figures here")
    args = parser.parse_args()
    if args.summary:
        rows = [json.loads(line) for path in args.summary for line in path.open()]
        # Rows of the first trace (before the report's figures were kept) carry only
        # the decomposition.
        full = [r for r in rows if "label" in r]
        trace = [r for r in rows if "label" not in r]
        print(table(full))
        figures = {"groups": by_group(full), "trace_only": summarise(trace) if trace else None}
        print(json.dumps(figures, indent=1))
        if args.json is not None:
            args.json.write_text(json.dumps(figures, indent=1) + "\n")
        return
    args.out.parent.mkdir(parents=True, exist_ok=True)
    for seed in args.seeds:
        for rule in args.rules:
            row = run_seed(seed, args.berries, args.marker_body, rule, args.label, args.fine_aim)
            with args.out.open("a") as f:
                f.write(json.dumps(row) + "\n")
            print(seed, rule, [round(e, 2) for e in row["true_mm"]], flush=True)


if __name__ == "__main__":
    main()
