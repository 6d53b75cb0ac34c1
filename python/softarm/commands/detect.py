"""``softarm detect IMAGE``: the berries a detector finds in one photo, printed and drawn."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, cast

from softarm.commands._args import image_file

if TYPE_CHECKING:
    from softarm.perception.berries import DetectorSettings


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``detect`` subcommand."""
    from softarm.perception.detector.choice import DEFAULT_DETECTOR, DETECTORS

    p = sub.add_parser(
        "detect",
        help="find the berries in one photo (printed, and drawn with --out)",
        description="Runs the berry detector on IMAGE (PNG, JPEG, BMP, TIFF or WebP) and prints "
        "each berry: its stage, score, centre and radius in pixels, and with --depth its "
        "position in the camera frame. --depth is a 16-bit PNG in millimetres or a .npy in "
        "metres, aligned with IMAGE; --camera a camera file (softarm JSON, OpenCV or ROS "
        "YAML; default: an ideal camera whose focal length is the image's longer side). "
        "See docs/perception.md.",
    )
    p.add_argument("image", type=Path, help="the photo")
    p.add_argument("--depth", type=Path, help="aligned depth image (16-bit PNG mm, or .npy m)")
    p.add_argument("--camera", type=Path, help="camera file of the photo")
    p.add_argument("--out", type=image_file, help="write the annotated picture here")
    p.add_argument("--detector", choices=DETECTORS, default=DEFAULT_DETECTOR, help="detector")
    add_split_touching(p)
    p.set_defaults(run=run)


def add_split_touching(p: argparse.ArgumentParser) -> None:
    """The ``--split-touching`` option of ``detect`` and ``detector evaluate``."""
    p.add_argument(
        "--split-touching",
        action="store_true",
        help="split fruit that touch at the necks of their shape (more of a cluster's fruit "
        "found, some precision lost; docs/perception-candidates.md, 'Splitting touching fruit')",
    )


def split_settings(args: argparse.Namespace) -> DetectorSettings | None:
    """The detector's settings ``--split-touching`` asks for (None: its own)."""
    from softarm.perception.detector.choice import SPLIT_TOUCHING

    return SPLIT_TOUCHING if args.split_touching else None


def run(args: argparse.Namespace) -> int:
    """Exit 0 once the berries are printed (none found is no error)."""
    import cv2
    import numpy as np
    import numpy.typing as npt

    from softarm.errors import InputError
    from softarm.files.images import read_image
    from softarm.perception._inputs import MAX_FRAME_PIXELS
    from softarm.perception.detector.choice import detector
    from softarm.perception.detector.draw import draw_detections, write_image
    from softarm.perception.detector.evaluate import read_depth
    from softarm.perception.detector.scoring import stage_of_detection
    from softarm.vision.camera_model import CameraModel

    # Bytes to OpenCV, never the path (a name that is not UTF-8 crashes cv2.imread), and
    # the header's size checked before anything is decoded.
    image = cast(
        npt.NDArray[np.uint8],
        read_image(args.image, "IMAGE", cv2.IMREAD_COLOR, max_pixels=MAX_FRAME_PIXELS),
    )
    h, w = image.shape[:2]
    camera = (
        CameraModel.load(args.camera) if args.camera is not None
        else CameraModel.ideal(float(max(w, h)), w, h)
    )  # fmt: skip
    depth = None
    if args.depth is not None:
        depth = read_depth(args.depth.parent, args.depth, (h, w))
        if depth is None:
            raise InputError(
                f"--depth {args.depth}: not a 16-bit PNG or .npy of the image's size {w}x{h}"
            )
    found = detector(args.detector).detect_berries(image, camera, depth, split_settings(args))
    dets = list(found)
    stages = [stage_of_detection(d) for d in dets]
    for d, stage in zip(dets, stages, strict=True):
        where = "" if d.position is None else " at ({:.3f}, {:.3f}, {:.3f}) m".format(*d.position)
        print(
            f"{stage:8s} score {d.score:.2f}  centre ({d.center[0]:.1f}, {d.center[1]:.1f}) px"
            f"  radius {d.radius:.1f} px{where}"
        )
    counts = ", ".join(f"{stages.count(s)} {s}" for s in ("ripe", "turning", "unripe"))
    print(f"detect: {len(dets)} berries ({counts}) by {args.detector} in {args.image}")
    if args.out is not None:
        write_image(args.out, draw_detections(image, dets))
        print(f"detect: annotated picture -> {args.out}")
    return 0
