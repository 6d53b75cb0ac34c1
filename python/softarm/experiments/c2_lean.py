"""The lean of C2's berry centres in the close view: at every C2 fix of fine positioning
(a traced harvest of the rendered bush), the detection's centre against the projection
of the berry's true centre from C2's true pose, and what makes the difference
(docs/harvest.md, "C2's centre in the close view").

``python -m softarm.experiments.c2_lean --seeds 1500-1509 --out FILE.json`` runs
``softarm harvest --sim --world bush --berries 6 --seed S --marker-body frustum`` for
each seed and taps C2's fixes. Each fix's errors are in px of C2's image (lens
distortion included), measured minus true:

- ``centre``: the detection's centre (what the harvest's ray goes through);
- ``perspective``: where a sphere of the berry's size centred on the true centre has
  its outline's centre (a sphere off the optical axis images as an ellipse whose centre
  lies outward of the centre's projection: f tan(theta) sin^2(alpha) / (cos^2(theta) -
  sin^2(alpha)), alpha the sphere's half angle);
- ``outline``: the centroid of the berry's visible geometry (the renderer's geom ids, no
  colour): what the drupelets' lumps and whatever is in front leave;
- ``refined``: :func:`~softarm.perception.berry_centre.silhouette_centre` on the
  detection (the detector refines only fruit up to ``MAX_REFINED_RADIUS``).

With ``--crops DIR`` each fix's window of the image and its mask are kept (one .npz a
seed) so that a centre rule can be compared on the same pixels without a harvest.
It lives above :mod:`softarm.perception` (which may not import the simulation).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from softarm.checks import FloatArray
from softarm.experiments.c1_lean import seed_range

__all__ = ["C2Trace", "outline_centre_offset", "summary"]

#: The berry's half width (m) with its drupelets (as c1_lean's).
BERRY_RADIUS = 0.0095 * 1.19
#: The window kept around a detection's box (px each side) with ``--crops``.
CROP_PAD = 14


def _unit(v: FloatArray) -> FloatArray:
    out: FloatArray = v / np.linalg.norm(v)
    return out


def outline_centre_offset(p: FloatArray, radius: float) -> FloatArray:
    """The centre of the outline of a sphere of ``radius`` (m) centred at ``p`` (camera
    frame, m) in the normalised image plane (z = 1), an ellipse whose centre lies
    outward of p's projection: along the radial direction at sin(2 theta) /
    (cos(2 theta) + cos(2 alpha)), theta p's angle from the optical axis, alpha the
    sphere's half angle (the mean of tan(theta - alpha) and tan(theta + alpha))."""
    d = float(np.linalg.norm(p))
    alpha = float(np.arcsin(min(radius / d, 1.0)))
    rho = float(np.hypot(p[0], p[1]))
    theta = float(np.arctan2(rho, p[2]))
    if rho == 0.0:
        return np.zeros(2)
    m = np.sin(2 * theta) / (np.cos(2 * theta) + np.cos(2 * alpha))
    out: FloatArray = np.array([p[0], p[1]]) / rho * m
    return out


@dataclass
class C2Trace:
    """Taps a simulated bush rig's C2 fixes (see the module docstring)."""

    rig: Any
    seed: int
    rows: list[dict[str, Any]] = field(default_factory=list)
    crops: list[dict[str, Any]] = field(default_factory=list)
    _image: Any = None

    def attach(self) -> None:
        """Wrap the vision's C2 read (to keep its frame) and berry selection (to tap
        each new RayCrossing's fixes)."""
        vision = self.rig.vision
        berry_c2, select = vision._berry_c2, vision.select

        def tapped_berry_c2(image: Any, T_c1_ee: Any) -> Any:
            self._image = image
            return berry_c2(image, T_c1_ee)

        def tapped_select(berry: Any) -> None:
            select(berry)
            track = vision._track
            if track is not None:
                fix = track.fix

                def tapped_fix(det: Any, T_base_camera: FloatArray, camera: Any) -> Any:
                    out = fix(det, T_base_camera, camera)
                    if out is not None and self._image is not None:
                        self._record(det)
                    return out

                track.fix = tapped_fix

        vision._berry_c2, vision.select = tapped_berry_c2, tapped_select

    def _record(self, det: Any) -> None:
        """One fix's centres against the truth."""
        from softarm.perception.berries import _centred

        rig, vision = self.rig, self.rig.vision
        scene = rig.scene
        truth = scene.truth_of(vision.selected.tag_id)
        if truth is None:
            return
        world = scene.world
        T_c2_base = np.linalg.inv(scene.plant.pose() @ vision._T_ee_c2)
        p = T_c2_base[:3, :3] @ truth.position + T_c2_base[:3, 3]
        model = vision.model2
        true_px = model.project(p[None, :])[0]
        xy = outline_centre_offset(p, BERRY_RADIUS)
        ellipse = model.project(np.array([[xy[0], xy[1], 1.0]]))[0]
        toward_sun = T_c2_base[:3, :3] @ -np.asarray(world.look.light_direction, float)
        sun = _unit(model.project((p + 0.01 * toward_sun)[None, :])[0] - true_px)
        image = np.asarray(self._image, dtype=np.uint8)
        blurred = np.asarray(cv2.GaussianBlur(image, (3, 3), 0), dtype=np.uint8)
        refined = np.array(_centred(det, blurred).center, dtype=float)
        row = {
            "seed": self.seed, "berry": int(truth.tag_id), "t": float(rig.clock.now()),
            "radius_px": float(det.radius), "depth_m": float(p[2]),
            "true_px": true_px.tolist(), "off_axis_px": (true_px - model.matrix[:2, 2]).tolist(),
            "centre": (np.asarray(det.center) - true_px).tolist(),
            "perspective": (ellipse - true_px).tolist(),
            "refined": (refined - true_px).tolist(),
            "outline": self._outline(world, truth.tag_id, true_px),
            "sun": sun.tolist(),
        }  # fmt: skip
        self.rows.append(row)
        self._crop(det, image, true_px, ellipse)

    def _outline(self, world: Any, tag_id: int, true_px: FloatArray) -> list[float]:
        """The centroid of the berry's visible geometry in C2's frame, from the true one."""
        import mujoco

        frame = world.c2_frame(truth=True)
        m = world.renderer.model
        names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, i) or "" for i in range(m.ngeom)]
        own = [i for i, n in enumerate(names) if n.startswith(f"berry{tag_id}_")]
        ys, xs = np.nonzero(np.isin(frame.geoms, own))
        if not xs.size:
            return [float("nan")] * 2
        out: list[float] = (np.array([xs.mean(), ys.mean()]) - true_px).tolist()
        return out

    def _crop(self, det: Any, image: Any, true_px: FloatArray, ellipse: FloatArray) -> None:
        x, y, w, h = det.box
        H, W = image.shape[:2]
        x0, y0 = max(x - CROP_PAD, 0), max(y - CROP_PAD, 0)
        x1, y1 = min(x + w + CROP_PAD, W), min(y + h + CROP_PAD, H)
        self.crops.append(
            {
                "colour": image[y0:y1, x0:x1].copy(),
                "mask": det.mask_window(x0, y0, x1, y1).copy(),
                "origin": (x0, y0),
                "centre": tuple(det.center),
                "true_px": true_px,
                "ellipse": ellipse,
                "radius": float(det.radius),
                "box": tuple(det.box),
            }
        )


def run_seed(seed: int, crops: Path | None) -> list[dict[str, Any]]:
    """One traced harvest (6 berries, frustum): its fixes' rows; their crops to
    ``crops``/c2_SEED.npz when given."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.sim.world import WorldName

    options = SimRigOptions(n_berries=6, seed=seed, world=WorldName.BUSH, marker_body="frustum")
    rig = build_sim_rig(options)
    trace = C2Trace(rig, seed)
    trace.attach()
    try:
        rig.run()
    finally:
        rig.close()
    if crops is not None:
        crops.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(crops / f"c2_{seed}.npz", crops=np.array(trace.crops, dtype=object))
    return trace.rows


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Medians over the fixes: each centre's error, its share towards the sun (positive)
    and outward (away from the principal point)."""
    out: dict[str, Any] = {
        "fixes": len(rows),
        "berries": len({(r["seed"], r["berry"]) for r in rows}),
    }
    if not rows:
        return out
    sun = np.array([r["sun"] for r in rows])
    outward = np.array([_unit(np.asarray(r["off_axis_px"])) for r in rows])
    for key in ("centre", "perspective", "outline", "refined"):
        e = np.array([r[key] for r in rows], dtype=float)
        out[key] = {
            "median_px": float(np.nanmedian(np.hypot(*e.T))),
            "along_sun_median_px": float(np.nanmedian((e * sun).sum(1))),
            "outward_median_px": float(np.nanmedian((e * outward).sum(1))),
        }
    out["radius_px_median"] = float(np.median([r["radius_px"] for r in rows]))
    out["off_axis_px_median"] = float(np.median([np.hypot(*r["off_axis_px"]) for r in rows]))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=seed_range, required=True, help="A-B, both included")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--crops", type=Path, help="keep each fix's window here")
    parser.add_argument("--label", default="")
    args = parser.parse_args()
    rows = [r for s in args.seeds for r in run_seed(s, args.crops)]
    result = {"label": args.label, "seeds": args.seeds, "summary": summary(rows), "rows": rows}
    args.out.write_text(json.dumps(result, indent=1) + "\n")
    print(json.dumps(result["summary"], indent=1))


if __name__ == "__main__":
    main()
