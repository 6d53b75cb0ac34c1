"""``softarm bench``: a quick timing of the main operations on this machine, for a user
who wants to know what to expect before wiring the arm into a loop. The reference figures,
with their baselines, come from ``make bench`` (criterion and pytest-benchmark) and are
recorded in BENCHMARKS.md; this command is a smoke-level check, not a replacement."""

from __future__ import annotations

import argparse
import json
import platform
import time
from collections.abc import Callable

import numpy as np

from softarm.commands._args import float_range
from softarm.formatting import rounded


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``bench`` subcommand."""
    p = sub.add_parser("bench", help="time the main operations on this machine")
    p.add_argument(
        "--seconds", type=float_range(0.0, 60.0), default=0.3, help="time budget per operation"
    )
    p.add_argument("--no-vision", action="store_true", help="skip the OpenCV timings")
    p.add_argument("--json", action="store_true", help="print the timings as JSON")
    p.set_defaults(run=run)


def _median_time(fn: Callable[[], object], budget: float) -> tuple[float, int]:
    """Median wall time of ``fn`` over batches filling ``budget`` seconds."""
    fn()  # warm up
    start = time.perf_counter()
    fn()
    once = max(time.perf_counter() - start, 1e-9)
    inner = max(1, int(0.01 / once))  # batches of ~10 ms, so timer overhead is negligible
    samples: list[float] = []
    deadline = time.perf_counter() + budget
    while time.perf_counter() < deadline or len(samples) < 3:
        t0 = time.perf_counter()
        for _ in range(inner):
            fn()
        samples.append((time.perf_counter() - t0) / inner)
    return float(np.median(samples)), inner * len(samples)


def _fmt(seconds: float) -> str:
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:8.2f} {unit}"
    return f"{seconds / 1e-9:8.0f} ns"


def _cases(with_vision: bool) -> list[tuple[str, Callable[[], object]]]:
    import softarm
    from softarm._core import paper_scenario

    arm = softarm.SoftArm.blackberry()
    q = np.array([0.010, 0.002, 0.025, 0.030, 0.012, 0.001, 0.005, 0.020, 0.015])
    batch = np.random.default_rng(0).uniform(arm.lower, arm.upper, size=(10_000, 9))
    goal = arm.forward(q + 0.003)
    resolver = softarm.Resolver(arm, mode="hybrid")
    chain = softarm.ArcChain([1.0, 1.0, 1.0])
    goal_tree, curves = paper_scenario("tree")
    q_chain = np.array([1.0, 0.4, 0.3, 1.0, 0.5, -1.0, 1.0, 0.6, 2.0])
    planner = softarm.PotentialFieldPlanner(chain)
    cases: list[tuple[str, Callable[[], object]]] = [
        ("SoftArm.forward", lambda: arm.forward(q)),
        ("SoftArm.jacobian", lambda: arm.jacobian(q)),
        ("SoftArm.forward_batch (10k poses)", lambda: arm.forward_batch(batch)),
        ("Resolver.step (hybrid, eq. 20)", lambda: resolver.step(q, goal)),
        (
            "closest(arc chain, 6 curves)",
            lambda: [softarm.closest(chain, q_chain, c) for c in curves],
        ),
        (
            "PotentialFieldPlanner.plan (sim 3)",
            lambda: planner.plan(chain.straight(), goal_tree, curves),
        ),
    ]
    if with_vision:
        import cv2

        from softarm.sim.camera import SyntheticCamera
        from softarm.sim.markers import cube_scene_markers
        from softarm.sim.vision_scenes import random_cube_pose
        from softarm.vision import CameraModel, MarkerCube

        cv2.setNumThreads(1)
        camera = CameraModel.ideal(900.0, 1280, 720, [-0.08, 0.03, 0.0005, -0.0005, 0.0])
        renderer = SyntheticCamera(camera, 1280, 720, noise_std=2.0, seed=1)
        cube = MarkerCube.standard()
        pose = random_cube_pose(np.random.default_rng(0))
        image = renderer.render(
            cube_scene_markers(cube.markers, cube.marker_length, cube.dictionary, pose)
        )
        cases.append(
            ("MarkerCube.estimate_pose (1280x720)", lambda: cube.estimate_pose(image, camera))
        )
    return cases


def run(args: argparse.Namespace) -> int:
    """Time each operation and print a table (or JSON)."""
    machine = platform.processor() or platform.machine()
    if args.json:
        rows = []
        for name, fn in _cases(not args.no_vision):
            median, calls = _median_time(fn, args.seconds)
            rows.append({"operation": name, "median_s": median, "calls": calls})
        doc = {"machine": machine, "python": platform.python_version(), "timings": rows}
        print(json.dumps(rounded(doc, 4), indent=2))
        return 0
    print(f"machine: {machine}, python {platform.python_version()}")
    print(f"{'operation':40s} {'median':>12s} {'calls':>8s}")
    for name, fn in _cases(not args.no_vision):
        median, calls = _median_time(fn, args.seconds)
        print(f"{name:40s} {_fmt(median)} {calls:8d}")
    print("reference figures with baselines: BENCHMARKS.md (make bench)")
    return 0
