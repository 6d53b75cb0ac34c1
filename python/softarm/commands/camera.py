"""``softarm camera calibrate``: a camera's intrinsics, or a stereo pair's, from images of
a ChArUco board, written as the OpenCV and ROS camera files that hw.toml names.

softarm camera calibrate shots/ --squares 7 5 --square 0.04 --marker 0.03 --out c2
softarm camera calibrate zed/ --stereo --squares 7 5 --square 0.04 --marker 0.03 --out c1
softarm camera calibrate left/ --right right/ --squares 7 5 ... --out c1

Mono writes ``OUT/camera.yml`` (OpenCV) and ``OUT/camera.yaml`` (ROS). Stereo (``--stereo``:
side-by-side frames, the ZED2 over USB video; ``--right``: a second camera's images, paired
with the first's in name order) writes ``left.yml``, ``right.yml`` (OpenCV),
``left.yaml``, ``right.yaml`` (ROS, rectified) and ``stereo.yml`` (both eyes and
``T_left_right``). Exit status 0, or 2 with one line naming the bad argument or file.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from softarm.commands._args import RawDefaultsFormatter, float_range, int_range, output_dir
from softarm.errors import InputError

#: The image files a folder contributes, by extension.
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``camera calibrate``."""
    p = sub.add_parser(
        "camera",
        help="calibrate a camera or a stereo pair from ChArUco images (calibrate)",
        description=__doc__,
        formatter_class=RawDefaultsFormatter,
    )
    actions = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    cal = actions.add_parser(
        "calibrate", help="intrinsics (and a stereo pair's baseline) from ChArUco images"
    )
    cal.add_argument("images", nargs="+", type=Path, help="image files or folders of them")
    stereo = cal.add_mutually_exclusive_group()
    stereo.add_argument(
        "--stereo", action="store_true", help="each image is a side-by-side frame (left|right)"
    )
    stereo.add_argument("--right", nargs="+", type=Path, help="the right eye's images")
    cal.add_argument(
        "--squares", nargs=2, type=int_range(2, 200), required=True,
        metavar=("COLUMNS", "ROWS"), help="the board's squares",
    )  # fmt: skip
    cal.add_argument("--square", type=float_range(1e-4, 10.0), required=True, help="square (m)")
    cal.add_argument("--marker", type=float_range(1e-4, 10.0), required=True, help="marker (m)")
    cal.add_argument("--dictionary", default="DICT_4X4_50", help="ArUco dictionary")
    cal.add_argument("--out", type=output_dir, required=True, help="folder for the files")
    cal.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Calibrate and write the files; 0 on success (errors are one line, exit 2)."""
    board = (tuple(args.squares), args.square, args.marker, args.dictionary)
    left = read_images(args.images, "images")
    if args.stereo or args.right is not None:
        right = read_images(args.right, "--right") if args.right is not None else None
        return _stereo(left, right, board, args.out)
    return _mono(left, board, args.out)


def read_images(paths: list[Path], what: str) -> list[Any]:
    """The images of ``paths`` (files, or folders of image files in name order)."""
    import cv2

    files: list[Path] = []
    for path in paths:
        if path.is_dir():
            files += sorted(f for f in path.iterdir() if f.suffix.lower() in IMAGE_SUFFIXES)
        else:
            files.append(path)
    if not files:
        raise InputError(f"{what}: no image files in {', '.join(map(str, paths))}")
    images = []
    for f in files:
        image = cv2.imread(str(f), cv2.IMREAD_COLOR) if f.is_file() else None
        if image is None:
            raise InputError(f"{what}: cannot read {str(f)!r} as an image")
        images.append(image)
    return images


def _mono(images: list[Any], board: tuple[Any, ...], out: Path) -> int:
    from softarm.vision import calibrate_charuco

    model, rms = calibrate_charuco(images, *board)
    out.mkdir(parents=True, exist_ok=True)
    model.save(out / "camera.yml")
    model.save(out / "camera.yaml")
    k = model.matrix
    print(f"{len(images)} images, rms {rms:.3f} px; fx {k[0, 0]:.2f}, fy {k[1, 1]:.2f}, "
          f"cx {k[0, 2]:.2f}, cy {k[1, 2]:.2f} px")  # fmt: skip
    print(f"wrote {out / 'camera.yml'} (OpenCV), {out / 'camera.yaml'} (ROS)")
    return 0


def _stereo(left: list[Any], right: list[Any] | None, board: tuple[Any, ...], out: Path) -> int:
    from softarm.vision.stereo_calibration import calibrate_stereo_charuco, split_side_by_side
    from softarm.vision.stereo_files import write_ros_stereo, write_stereo

    if right is None:
        halves = [split_side_by_side(f, f"images[{k}]") for k, f in enumerate(left)]
        left, right = [h[0] for h in halves], [h[1] for h in halves]
    model, rms = calibrate_stereo_charuco(left, right, *board)
    out.mkdir(parents=True, exist_ok=True)
    model.left.save(out / "left.yml")
    model.right.save(out / "right.yml")
    write_ros_stereo(model, out / "left.yaml", out / "right.yaml")
    write_stereo(model, out / "stereo.yml")
    fl, fr = model.left.matrix[0, 0], model.right.matrix[0, 0]
    print(f"{len(left)} stereo views, rms {rms:.3f} px; fx left {fl:.2f}, right {fr:.2f} px; "
          f"baseline {1e3 * model.baseline:.2f} mm")  # fmt: skip
    print(f"wrote {out}/left.yml, right.yml (OpenCV), left.yaml, right.yaml (ROS), stereo.yml")
    return 0
