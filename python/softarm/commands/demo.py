"""``softarm demo``: the default arm's pose and Jacobian, and a plot of the arm."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from softarm._core import SoftArm


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``demo`` subcommand."""
    p = sub.add_parser("demo", help="print the default arm's pose and Jacobian, plot it")
    p.add_argument("--out", type=Path, default=Path("out"), help="output folder")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Print FK and the Jacobian at a few configurations and save ``arm.png``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from softarm.viz.arm import draw_arm, set_equal_3d

    arm = SoftArm.blackberry()
    np.set_printoptions(precision=4, suppress=True, linewidth=120)
    configs = {
        "straight": np.zeros(arm.n_actuators),
        "bent": np.array([0.0, 0.02, 0.03, 0.03, 0.0, 0.01, 0.0, 0.033, 0.0]),
        "mid-range": (arm.lower + arm.upper) / 2,
    }
    args.out.mkdir(parents=True, exist_ok=True)
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    pts = []
    for name, q in configs.items():
        pose, jac = arm.forward_jacobian(q)
        print(f"== {name}: q = {q} m")
        print("pose T_base_ee =\n", pose)
        print("Jacobian (6 x 9, rows vx vy vz wx wy wz) =\n", jac)
        draw_arm(ax, arm, q, label=name)
        pts.append(arm.backbone(q, 30))
    set_equal_3d(ax, np.concatenate(pts))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title("SoftArm.blackberry()")
    path = args.out / "arm.png"
    fig.savefig(path, dpi=120)
    print(f"saved {path}")
    return 0
