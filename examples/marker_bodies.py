"""Draw the marker bodies (softarm.vision.marker_body) in three views with their sizes:
the picture in docs/hardware.md, "The marker body".

    python examples/marker_bodies.py --out docs/img
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from softarm.vision import MarkerCube


def main() -> None:
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--out", type=Path, default=Path("out/marker_bodies"), help="output folder")
    p.add_argument("--marker", type=float, default=0.08, help="the tags' side (m)")
    args = p.parse_args()

    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle

    from softarm.vision.marker_body import MARKER_BODIES, marker_body, panel_corners

    views = {  # title: the direction towards the viewer, in the body frame
        "side (from -y; the gripper up)": np.array([0.0, -1.0, 0.0]),
        "from behind (from the arm, along +z)": np.array([0.0, 0.0, -1.0]),
        "as C1 sees it (50 deg off the back axis)": _towards(50.0, 225.0),
    }
    fig, axes = plt.subplots(len(MARKER_BODIES), len(views), figsize=(11, 7.4))
    for row, name in zip(axes, MARKER_BODIES, strict=True):
        body = marker_body(name, args.marker)
        panels = 1e3 * panel_corners(body)
        tags = 1e3 * _tag_squares(body)
        normals = [body.markers[i][:3, 2] for i in sorted(body.markers)]
        for ax, (title, viewer) in zip(row, views.items(), strict=True):
            project = _projection(viewer)
            for panel, tag, normal in zip(panels, tags, normals, strict=True):
                if normal @ viewer > 1e-9:  # facing the viewer: the tag shows
                    ax.fill(*project(panel).T, facecolor="0.93", edgecolor="0.3", lw=1)
                    ax.fill(*project(tag).T, facecolor="0.15", edgecolor="0.15", lw=0.5)
                else:  # its back or its edge: the outline
                    ax.fill(*project(panel).T, fill=False, edgecolor="0.6", lw=0.8)
            if viewer[2] == -1.0:
                ax.add_patch(Circle((0, 0), 36, fill=False, ls="--", color="tab:blue"))
            ax.set_aspect("equal")
            ax.set_title(f"{name}: {title}", fontsize=8)
            ax.tick_params(labelsize=7)
        size = np.ptp(panels.reshape(-1, 3), axis=0)
        row[0].set_ylabel(
            f"{name}: {size[0]:.0f} x {size[1]:.0f} x {size[2]:.0f} mm\n"
            f"tags {1e3 * args.marker:.0f} mm (mm)",
            fontsize=8,
        )
    fig.suptitle(
        "Marker bodies (mm): tags dark on their printed squares, backs and edges outlined; "
        "the arm's tube (r 36 mm) dashed",
        fontsize=9,
    )
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "marker_bodies.png", dpi=90)
    print(args.out / "marker_bodies.png")


def _tag_squares(body: MarkerCube) -> np.ndarray:
    """(N, 4, 3) corners of each tag (the black square) in the body frame."""
    return np.array([body.object_points(i) for i in sorted(body.markers)])


def _towards(off_axis: float, azimuth: float) -> np.ndarray:
    """The unit direction ``off_axis`` degrees from the back axis (-z) at ``azimuth``."""
    t, a = np.radians(off_axis), np.radians(azimuth)
    return np.array([np.sin(t) * np.cos(a), np.sin(t) * np.sin(a), -np.cos(t)])


def _projection(viewer: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """Orthographic projection onto the picture plane of a viewer towards ``viewer``:
    the body's +z up where it can be (+y when looking along z)."""
    up = np.array([0.0, 0.0, 1.0]) if abs(viewer[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    up = up - (up @ viewer) * viewer
    up /= np.linalg.norm(up)
    right = np.cross(up, viewer)
    return lambda points: points @ np.column_stack([right, up])


if __name__ == "__main__":
    main()
