"""Wall time per simulated berry, before and after the faster synthetic cameras (BENCHMARKS.md).

Each run is one bush (``SimRigOptions(n_berries, seed)``, what ``softarm harvest --sim``
does) in a fresh process. The variants run in turn, seed by seed, so that they share the
machine's load:

- ``crop``: this tree; the cameras render and search only the window that holds the
  markers (``SimCameras.crop``, the default);
- ``full``: this tree with ``SimCameras.crop = False`` (whole frames);
- ``baseline``: the tree given by ``--baseline DIR`` (its ``python/`` holds a built
  softarm), for instance a git worktree of the commit before the change;
- ``<variant>+noise``: with ``--noise-control``, the first variant again with the cameras'
  noise generator seeded differently: how far the results move for pixel noise alone.

It prints wall and CPU seconds per berry (the run only; building the rig is reported on
its own), and compares each report with the first variant's: the harvested set and the
fine-positioning errors. The reports go to ``--out``.

    git worktree add /tmp/before HEAD   # then the camera and vision files as before:
    git -C /tmp/before checkout c200ecf -- python/softarm/sim/camera.py \\
        python/softarm/sim/markers.py python/softarm/sim/rig_cameras.py \\
        python/softarm/vision/{detector,refine,_checks,camera_model,baseline}.py
    cp python/softarm/_core*.so /tmp/before/python/softarm/
    python examples/bench_sim_rig.py --seeds 100 101 --berries 4 \\
        --baseline /tmp/before --noise-control
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

from softarm.commands._args import (
    Parser,
    RawDefaultsFormatter,
    int_range,
    non_negative_int,
    output_dir,
)

# Runs in the child process, against whichever softarm its PYTHONPATH selects. It must
# work with trees that predate SimCameras.crop.
_CHILD = r"""
import dataclasses, json, sys, time
t0, c0 = time.perf_counter(), time.process_time()
import cv2
cv2.setNumThreads(1)
import softarm.harvest.rigs.sim.rig as sr
seed, berries, crop, noise_offset, report = (
    int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], int(sys.argv[4]), sys.argv[5])
if crop != "default":
    cameras = sr.default_cameras
    sr.default_cameras = lambda *a, **k: dataclasses.replace(
        cameras(*a, **k), crop=(crop == "crop"))
if noise_offset:
    vision = sr.sim_vision
    sr.sim_vision = lambda *a, seed=0, **k: vision(*a, seed=seed + noise_offset, **k)
rig = sr.build_sim_rig(sr.SimRigOptions(n_berries=berries, seed=seed))
t1, c1 = time.perf_counter(), time.process_time()
result = rig.run()
t2, c2 = time.perf_counter(), time.process_time()
result.save(report)
print(json.dumps({"setup_wall": t1 - t0, "setup_cpu": c1 - c0, "wall": t2 - t1,
                  "cpu": c2 - c1, "steps": sum(b.steps for b in result.berries)}))
"""


def run_one(
    tree: Path, seed: int, berries: int, crop: str, noise_offset: int, report: Path
) -> dict:
    """One bush in a fresh process on ``tree``'s softarm; timings and the report path."""
    env = dict(os.environ, PYTHONPATH=str(tree / "python"))
    args = [str(seed), str(berries), crop, str(noise_offset), str(report)]
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, *args], env=env, capture_output=True, text=True
    )
    if proc.returncode != 0:
        raise RuntimeError(f"run on {tree} (seed {seed}) failed:\n{proc.stderr[-2000:]}")
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["report"] = json.loads(report.read_text())
    return out


def _mm(berry: dict) -> float | None:
    err = berry["true_position_error_mm"]
    return None if err is None else round(err, 3)


def main(argv: list[str] | None = None) -> int:
    ap = Parser(
        prog="bench_sim_rig.py",
        description=__doc__.split("\n\n")[0] + "\n\n" + __doc__.split("\n\n")[-1],
        formatter_class=RawDefaultsFormatter,
    )
    ap.add_argument("--seeds", type=non_negative_int, nargs="+", default=[100, 101], help="bushes")
    ap.add_argument("--berries", type=int_range(1, 100), default=4, help="berries per bush")
    ap.add_argument("--baseline", type=Path, help="source tree to compare with (see above)")
    ap.add_argument(
        "--variants", nargs="+", choices=["baseline", "full", "crop"],
        default=["baseline", "crop"], help="what to run ('baseline' needs --baseline)",
    )  # fmt: skip
    ap.add_argument("--noise-control", action="store_true", help="also run the noise control")
    ap.add_argument("--out", type=output_dir, default="out/bench_sim_rig", help="reports")
    args = ap.parse_args(argv)
    if "baseline" in args.variants and args.baseline is None:
        ap.error("--variants baseline needs --baseline DIR")
    if args.baseline is not None and not (args.baseline / "python" / "softarm").is_dir():
        ap.error(f"--baseline: {str(args.baseline)!r} has no python/softarm")
    here = Path(__file__).resolve().parent.parent
    plan = [
        (v, args.baseline if v == "baseline" else here, "default" if v == "baseline" else v, 0)
        for v in args.variants
    ]
    if args.noise_control:
        name, tree, crop, _ = plan[0]
        plan.append((f"{name}+noise", tree, crop, 7919))
    args.out.mkdir(parents=True, exist_ok=True)
    runs: dict[str, list[dict]] = {name: [] for name, *_ in plan}
    for seed in args.seeds:
        for name, tree, crop, offset in plan:
            report = args.out / f"{name}-seed{seed}.json"
            runs[name].append(run_one(tree, seed, args.berries, crop, offset, report))
            r = runs[name][-1]
            print(
                f"seed {seed} {name:14s} wall {r['wall']:6.1f} s, cpu {r['cpu']:6.1f} s, "
                f"{r['steps']} steps",
                flush=True,
            )
    n = args.berries * len(args.seeds)
    first = plan[0][0]
    print(f"\n{n} berries (seeds {', '.join(map(str, args.seeds))}), per berry:\n")
    print("| variant | wall (s) | CPU (s) | ms per control period | build wall (s) |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for name, rows in runs.items():
        wall, cpu = sum(r["wall"] for r in rows), sum(r["cpu"] for r in rows)
        steps = sum(r["steps"] for r in rows)
        build = statistics.median(r["setup_wall"] for r in rows)
        print(
            f"| {name} | {wall / n:.2f} | {cpu / n:.2f} | {1e3 * wall / steps:.1f} | {build:.2f} |"
        )
    print(f"\nagainst {first}:")
    for name, rows in runs.items():
        if name == first:
            continue
        for ref, got, seed in zip(runs[first], rows, args.seeds, strict=True):
            a, b = ref["report"]["berries"], got["report"]["berries"]
            same = [x["harvested"] for x in a] == [y["harvested"] for y in b]
            dpos = max(
                abs((x["true_position_error_mm"] or 0.0) - (y["true_position_error_mm"] or 0.0))
                for x, y in zip(a, b, strict=True)
            )
            print(
                f"  {name} seed {seed}: same harvested set {same}, errors (mm) "
                f"{[_mm(x) for x in a]} vs "
                f"{[_mm(y) for y in b]} (max diff {dpos:.3f})"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
