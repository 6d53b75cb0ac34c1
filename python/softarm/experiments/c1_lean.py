"""The lean of C1's berry centres: each ripe berry's measured centre in C1's static view
against the projection of its true centre, and the error's share along the sun's
direction in the image, the approach's and the principal point's (docs/harvest.md,
"The lean of C1's centre").

``python -m softarm.experiments.c1_lean --seeds 1500-1509 --out FILE.json`` builds each
seed's simulated rig as ``softarm harvest --sim --world bush --berries 6`` does (the
frustum), renders C1's pair with the arm at rest and locates the berries as the harvest
does (:func:`~softarm.perception.stereo.locate_berries`). Errors are in px of C1's
rectified left image: ``left`` its centre, ``ray`` C1's ray (from the baseline's middle
through the triangulated berry, the harvest's), ``outline`` the centroid of the berry's
visible geometry (the renderer's geom ids, no colour), which shows what the drupelets'
lumps and the leaves in front leave without any threshold.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from softarm.checks import FloatArray

#: A detection is a true berry's when its centre lies this close (px) to its projection.
MATCH_PX = 3.0
#: The berry's half widths (m) with its drupelets, for the perspective term (mjcf).
BERRY_RADIUS = 0.0095 * 1.19


def _project(P1: FloatArray, p: FloatArray) -> FloatArray:
    q = P1[:3, :3] @ p
    out: FloatArray = q[:2] / q[2]
    return out


def _unit(v: FloatArray) -> FloatArray:
    out: FloatArray = v / np.linalg.norm(v)
    return out


def seed_rows(seed: int) -> list[dict[str, Any]]:
    """The ripe berries of ``seed``'s bush that C1 locates, each with its errors."""
    import mujoco

    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.perception.stereo import locate_berries
    from softarm.sim.world import WorldName

    options = SimRigOptions(n_berries=6, seed=seed, world=WorldName.BUSH, marker_body="frustum")
    rig = build_sim_rig(options)
    try:
        world = rig.world.scene.world  # type: ignore[union-attr]
        left, right = world.c1(truth=True)
        dets = locate_berries(left.colour, right.colour, world.stereo)
        mx, my = world.stereo.rectification.maps[0]
        assert left.geoms is not None  # asked for (truth=True)
        ids = np.asarray(cv2.remap(left.geoms.astype(np.float32), mx, my, cv2.INTER_NEAREST))
        m = world.renderer.model
        names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, i) or "" for i in range(m.ngeom)]
        ripe = [b for b in rig.bush.berries if b.ripeness >= 0.5]
        rows = [_row(world, b, dets, ids.astype(np.int32), names) for b in ripe]
    finally:
        rig.close()
    return [dict(r, seed=seed) for r in rows if r is not None]


def _row(
    world: Any, berry: Any, dets: list[Any], ids: Any, names: list[str]
) -> dict[str, Any] | None:
    """One berry's errors (px), None where C1 does not place it."""
    stereo = world.stereo
    rect = stereo.rectification
    to_rect = rect.R1 @ np.linalg.inv(stereo.T_base_left)[:3, :]  # base -> rectified left
    p = to_rect @ np.append(berry.position, 1.0)
    true_px = _project(rect.P1, p)
    placed = [d for d in dets if d.ripeness == "ripe" and d.position is not None]
    near = [d for d in placed if np.hypot(*(np.asarray(d.center) - true_px)) < MATCH_PX]
    if not near:
        return None
    det = min(near, key=lambda d: float(np.hypot(*(np.asarray(d.center) - true_px))))
    middle = 0.5 * rect.R1 @ stereo.T_left_right[:3, 3]  # the ray's origin
    q, t = to_rect @ np.append(det.position, 1.0) - middle, p - middle
    ray = rect.focal * (q[:2] / q[2] - t[:2] / t[2])
    own = [i for i, n in enumerate(names) if n.startswith(f"berry{berry.tag_id}_")]
    ys, xs = np.nonzero(np.isin(ids, own))
    outline = np.array([xs.mean(), ys.mean()]) - true_px if xs.size else np.full(2, np.nan)
    R = to_rect[:, :3]
    toward_sun = -np.asarray(world.look.light_direction, float)
    sun = _unit(_project(rect.P1, p + 0.01 * R @ toward_sun) - true_px)
    approach = _unit(_project(rect.P1, p + 0.01 * R @ np.asarray(berry.approach)) - true_px)
    off_axis = true_px - rect.P1[:2, 2]
    left = np.asarray(det.center) - true_px
    return {
        "berry": int(berry.tag_id), "radius_px": float(det.radius), "depth_m": float(p[2]),
        "left": left.tolist(), "ray": ray.tolist(), "outline": outline.tolist(),
        "sun": sun.tolist(), "approach": approach.tolist(), "off_axis_px": off_axis.tolist(),
        # A sphere's image centre lies off its centre's projection, away from the
        # principal point, by about f (r/d)^2 tan(theta).
        "perspective_px": float(np.hypot(*off_axis) * (BERRY_RADIUS / np.linalg.norm(p)) ** 2),
    }  # fmt: skip


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Medians over the berries: each error's size and its share along the sun's
    direction (towards it: positive), the approach's, and away from the principal point."""
    out: dict[str, Any] = {"berries": len(rows)}
    if not rows:
        return out
    sun = np.array([r["sun"] for r in rows])
    approach = np.array([r["approach"] for r in rows])
    outward = np.array([_unit(np.asarray(r["off_axis_px"])) for r in rows])
    for key in ("left", "ray", "outline"):
        e = np.array([r[key] for r in rows])
        along_sun = (e * sun).sum(1)
        out[key] = {
            "median_px": float(np.nanmedian(np.hypot(*e.T))),
            "along_sun_median_px": float(np.nanmedian(along_sun)),
            "away_from_sun": int(np.sum(along_sun < 0)),
            "along_approach_median_px": float(np.nanmedian((e * approach).sum(1))),
            "outward_median_px": float(np.nanmedian((e * outward).sum(1))),
        }
    out["perspective_px_median"] = float(np.median([r["perspective_px"] for r in rows]))
    return out


def seed_range(text: str) -> list[int]:
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=seed_range, required=True, help="A-B, both included")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--label", default="")
    args = parser.parse_args()
    rows = [r for s in args.seeds for r in seed_rows(s)]
    result = {"label": args.label, "seeds": args.seeds, "summary": summary(rows), "rows": rows}
    args.out.write_text(json.dumps(result, indent=1) + "\n")
    print(json.dumps(result["summary"], indent=1))


if __name__ == "__main__":
    main()
