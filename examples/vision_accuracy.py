# ruff: noqa: E501
"""Accuracy table of the vision path on synthetic images (BENCHMARKS.md).

Eye-to-hand: 1280x720, f = 900 px, mild distortion, the standard 80 mm marker cube about
1 m away in random poses, pixel noise 2 gray levels. Compares softarm's MarkerCube with
plain OpenCV (Board + solvePnP; the default detector, then with OpenCV's own
CORNER_REFINE_SUBPIX and CORNER_REFINE_APRILTAG corner refinements) and with the noise
limit: ideal corners plus Gaussian noise of the measured (robust) corner error std, solved
by the same PnP. Eye-in-hand: a 12 mm berry tag 3–10 cm away. Prints Markdown tables;
writes nothing.

    python examples/vision_accuracy.py --poses 200 --seed 0
"""

from __future__ import annotations

import sys

import numpy as np

from softarm.commands._args import Parser, int_range, non_negative_int
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker, cube_scene_markers
from softarm.sim.vision_scenes import random_cube_pose, random_facing_pose
from softarm.vision import (
    CameraModel,
    Detection,
    MarkerCube,
    MarkerDetector,
    OpenCVBaseline,
    estimate_marker_poses,
)
from softarm.vision.poses import rotation_angle, transform_points


def main(argv: list[str] | None = None) -> int:
    parser = Parser(prog="vision_accuracy.py", description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--poses", type=int_range(1, 100_000), default=200, help="random cube poses"
    )
    parser.add_argument("--seed", type=non_negative_int, default=0, help="seed of the poses")
    args = parser.parse_args(argv)
    n = args.poses
    camera = CameraModel.ideal(900.0, 1280, 720, [-0.08, 0.03, 0.0005, -0.0005, 0.0])
    renderer = SyntheticCamera(camera, 1280, 720, noise_std=2.0, seed=1)
    cube = MarkerCube.standard()
    # OpenCV with its default detector, and with each of its own corner refinements.
    baselines = {r: OpenCVBaseline(cube, r) for r in ("none", "subpix", "apriltag")}
    rng = np.random.default_rng(args.seed)
    ours, corner_err, poses = [], [], []
    base: dict[str, list] = {r: [] for r in baselines}
    for _ in range(n):
        pose = random_cube_pose(rng)
        poses.append(pose)
        img = renderer.render(cube_scene_markers(cube.markers, 0.08, cube.dictionary, pose))
        for det in cube.detector.detect(img, camera):
            truth = camera.project(transform_points(pose, cube.object_points(det.marker_id)))
            corner_err.append(det.corners - truth)
        ours.append(_errors(cube.estimate_pose(img, camera), pose))
        for r, baseline in baselines.items():
            base[r].append(_errors(baseline.estimate_pose(img, camera), pose))
    err = np.concatenate(corner_err).ravel()
    sigma = 1.4826 * np.median(np.abs(err - np.median(err)))  # robust std (MAD)
    bound = _noise_limit(cube, camera, poses, sigma, rng)
    bound_plain = _noise_limit(cube, camera, poses, float(err.std()), rng)
    print(f"corner error: robust std {sigma:.4f} px, plain std {err.std():.4f} px, N = {n} poses")
    print(
        "| method | median position error (mm) | median orientation error (°) | p90 orientation (°) | failures |"
    )
    print("| --- | --- | --- | --- | --- |")
    for name, rows in (
        ("noise limit, robust σ (ideal corners + σ)", bound),
        ("noise limit, plain std", bound_plain),
        ("softarm MarkerCube", ours),
        ("plain OpenCV Board + solvePnP", base["none"]),
        ("OpenCV + CORNER_REFINE_SUBPIX", base["subpix"]),
        ("OpenCV + CORNER_REFINE_APRILTAG", base["apriltag"]),
    ):
        a = np.array(rows)
        print(
            f"| {name} | {np.nanmedian(a[:, 0]) * 1e3:.3f} | {np.nanmedian(a[:, 1]):.3f} | "
            f"{np.nanpercentile(a[:, 1], 90):.3f} | {int(np.isnan(a[:, 0]).sum())} |"
        )
    detector = MarkerDetector()
    berry = []
    for _ in range(50):
        pose = random_facing_pose(rng, (0.03, 0.10))
        img = renderer.render([SceneMarker(5, "DICT_4X4_50", 0.012, pose)])
        est = estimate_marker_poses(detector.detect(img, camera), camera, 0.012)
        berry.append(_errors(est.get(5), pose))
    b = np.array(berry)
    print(
        f"| berry tag 12 mm at 3–10 cm | {np.nanmedian(b[:, 0]) * 1e3:.3f} (max {np.nanmax(b[:, 0]) * 1e3:.3f}) | "
        f"{np.nanmedian(b[:, 1]):.3f} | {np.nanpercentile(b[:, 1], 90):.3f} | {int(np.isnan(b[:, 0]).sum())} |"
    )
    return 0


def _noise_limit(
    cube: MarkerCube, camera: CameraModel, poses: list, sigma: float, rng: np.random.Generator
) -> list[tuple[float, float]]:
    """Median-error limit: ideal projected corners plus N(0, σ²) noise, same joint PnP."""
    rows = []
    for pose in poses:
        dets = []
        for i in cube.markers:
            m = pose @ cube.markers[i]
            if -m[:3, 2] @ m[:3, 3] / np.linalg.norm(m[:3, 3]) < np.cos(np.radians(80)):
                continue  # faces seen at > 80° are not detected either
            truth = camera.project(transform_points(pose, cube.object_points(i)))
            dets.append(Detection(i, truth + rng.normal(0, sigma, truth.shape)))
        fit = cube.estimate(dets, camera)
        rows.append(_errors(None if fit is None else fit.T_camera_cube, pose))
    return rows


def _errors(est: np.ndarray | None, pose: np.ndarray) -> tuple[float, float]:
    if est is None:
        return (np.nan, np.nan)
    return (
        float(np.linalg.norm(est[:3, 3] - pose[:3, 3])),
        float(np.degrees(rotation_angle(est, pose))),
    )


if __name__ == "__main__":
    sys.exit(main())
