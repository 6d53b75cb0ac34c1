"""``softarm camera calibrate``: a camera's intrinsics, or a stereo pair's, from images of
a ChArUco board, written as the OpenCV and ROS camera files that hw.toml names.

softarm camera calibrate shots/ --squares 7 5 --square 0.04 --marker 0.03 --out c2
softarm camera calibrate zed/ --stereo --squares 7 5 --square 0.04 --marker 0.03 --out c1
softarm camera calibrate left/ --right right/ --squares 7 5 ... --out c1
softarm camera board --out charuco_board.png   # the board those commands expect, to print

Mono writes ``OUT/camera.yml`` (OpenCV) and ``OUT/camera.yaml`` (ROS). Stereo (``--stereo``:
side-by-side frames, the ZED2 over USB video; ``--right``: a second camera's images, paired
with the first's in name order) writes ``left.yml``, ``right.yml`` (OpenCV),
``left.yaml``, ``right.yaml`` (ROS, rectified) and ``stereo.yml`` (both eyes and
``T_left_right``). Exit status 0; 1 when the calibration is not converged (its data
fails a check of :mod:`softarm.vision.calibration_checks`: views not tilted enough,
uncertain intrinsics, an RMS above 2 px, an implausible baseline, swapped eyes), each
problem told and no file written; 2 with one line naming the bad argument or file (fewer
than 3 distinct views, one image given for both eyes).

Each image is read when it is used and not kept (only its corners are), through
:func:`softarm.files.images.read_image`: an image of more than 20 M pixels is refused
before it is decoded.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, overload

from softarm.commands._args import RawDefaultsFormatter, float_range, int_range, output_dir
from softarm.commands.camera_board import add_board_parser
from softarm.errors import InputError

#: The image files a folder contributes, by extension.
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")
#: Most pixels a calibration image may have: 20 M (a 4K pair side by side is 16.6 M).
#: The ChArUco detector needs about 25 bytes a pixel on a busy image.
MAX_PIXELS = 20_000_000


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``camera calibrate``."""
    p = sub.add_parser(
        "camera",
        help="calibrate a camera or a stereo pair from ChArUco images (calibrate); write "
        "the board to print (board)",
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
    add_board_parser(actions)  # camera board: the board to print


def run(args: argparse.Namespace) -> int:
    """Calibrate and write the files; 0 on success, 1 when not converged (errors are
    one line, exit 2)."""
    if args.marker >= args.square:
        raise InputError(f"--marker {args.marker:g} must be smaller than --square {args.square:g}")
    from softarm.vision.calibration_checks import CalibrationNotConverged

    board = (tuple(args.squares), args.square, args.marker, args.dictionary)
    left = read_images(args.images, "images")
    try:
        if args.stereo or args.right is not None:
            right = read_images(args.right, "--right") if args.right is not None else None
            return _stereo(left, right, board, args.out)
        return _mono(left, board, args.out)
    except CalibrationNotConverged as exc:
        for problem in exc.problems:
            print(f"softarm camera: not converged: {problem}", file=sys.stderr)
        where = shown(args.out)
        print(f"calibration NOT converged (rms {exc.rms:.3f} px): no files written to {where}")
        return 1


class ImageFiles(Sequence[Any]):
    """Image files read on demand (the last one kept, for the two halves of a
    side-by-side frame): a calibration holds one image at a time, not all of them."""

    def __init__(self, files: list[Path], what: str) -> None:
        self.files, self.what = files, what
        self._last: tuple[int, Any] | None = None

    def __len__(self) -> int:
        return len(self.files)

    @overload
    def __getitem__(self, k: int) -> Any: ...
    @overload
    def __getitem__(self, k: slice) -> list[Any]: ...
    def __getitem__(self, k: int | slice) -> Any:
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        from softarm.files.images import read_image

        k = range(len(self))[k]  # negative indices; IndexError past the end
        if self._last is None or self._last[0] != k:
            self._last = (
                k,
                read_image(self.files[k], f"{self.what}: image", 1, max_pixels=MAX_PIXELS),
            )
        return self._last[1]


class Halves(Sequence[Any]):
    """One half (0: left, 1: right) of each side-by-side frame of ``frames``."""

    def __init__(self, frames: Sequence[Any], side: int) -> None:
        self.frames, self.side = frames, side

    def __len__(self) -> int:
        return len(self.frames)

    @overload
    def __getitem__(self, k: int) -> Any: ...
    @overload
    def __getitem__(self, k: slice) -> list[Any]: ...
    def __getitem__(self, k: int | slice) -> Any:
        from softarm.vision.stereo_calibration import split_side_by_side

        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        return split_side_by_side(self.frames[k], f"images[{k}]")[self.side]


def shown(path: Path) -> str:
    """``path`` for the terminal: bytes that are not UTF-8 as ``\\xff`` escapes (printed
    as they are, they would stop the command with a UnicodeEncodeError)."""
    return str(path).encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def read_images(paths: list[Path], what: str) -> ImageFiles:
    """The images of ``paths`` (files, or folders of image files in name order), each
    read when it is used."""
    files: list[Path] = []
    for path in paths:
        if path.is_dir():
            files += sorted(f for f in path.iterdir() if f.suffix.lower() in IMAGE_SUFFIXES)
        elif not path.exists():  # a typo'd folder is named as missing, not as an image
            raise InputError(f"{what}: {str(path)!r}: no such file or folder")
        else:
            files.append(path)
    if not files:
        raise InputError(f"{what}: no image files in {', '.join(map(str, paths))}")
    return ImageFiles(files, what)


def _mono(images: Sequence[Any], board: tuple[Any, ...], out: Path) -> int:
    from softarm.vision import calibrate_charuco

    model, rms = calibrate_charuco(images, *board)
    out.mkdir(parents=True, exist_ok=True)
    model.save(out / "camera.yml")
    model.save(out / "camera.yaml")
    k = model.matrix
    print(f"{len(images)} images, rms {rms:.3f} px; fx {k[0, 0]:.2f}, fy {k[1, 1]:.2f}, "
          f"cx {k[0, 2]:.2f}, cy {k[1, 2]:.2f} px")  # fmt: skip
    print(f"wrote {shown(out / 'camera.yml')} (OpenCV), {shown(out / 'camera.yaml')} (ROS)")
    return 0


def _stereo(
    left: Sequence[Any], right: Sequence[Any] | None, board: tuple[Any, ...], out: Path
) -> int:
    from softarm.vision.stereo_calibration import calibrate_stereo_charuco
    from softarm.vision.stereo_files import write_ros_stereo, write_stereo

    if right is None:
        left, right = Halves(left, 0), Halves(left, 1)
    model, rms = calibrate_stereo_charuco(left, right, *board)
    out.mkdir(parents=True, exist_ok=True)
    model.left.save(out / "left.yml")
    model.right.save(out / "right.yml")
    write_ros_stereo(model, out / "left.yaml", out / "right.yaml")
    write_stereo(model, out / "stereo.yml")
    fl, fr = model.left.matrix[0, 0], model.right.matrix[0, 0]
    print(f"{len(left)} stereo views, rms {rms:.3f} px; fx left {fl:.2f}, right {fr:.2f} px; "
          f"baseline {1e3 * model.baseline:.2f} mm")  # fmt: skip
    print(
        f"wrote {shown(out)}/left.yml, right.yml (OpenCV), left.yaml, right.yaml (ROS), stereo.yml"
    )
    return 0
