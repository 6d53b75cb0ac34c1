"""``softarm camera board``: the ChArUco board ``softarm camera calibrate`` expects, as a
PNG to print. Its defaults are the board of docs/getting-started.md (7 x 5 squares of
40 mm, markers of 30 mm, DICT_4X4_50), drawn at ``--dpi`` so that printed at 100 % scale
its squares have that size; measure a printed square and pass what you measure as
``--square`` (and ``--marker``) to ``camera calibrate``."""

from __future__ import annotations

import argparse
from typing import Any

from softarm.commands._args import float_range, image_file, int_range
from softarm.errors import InputError

#: Millimetres per inch, for the print resolution.
MM_PER_INCH = 25.4
#: Most pixels a board image may have (a 4 x 3 m board at 300 dpi is 16 M).
MAX_PIXELS = 20_000_000


def add_board_parser(actions: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``camera board`` under ``softarm camera``."""
    p = actions.add_parser(
        "board",
        help="write the ChArUco board to print, as a PNG",
        description=__doc__,
    )
    p.add_argument("--out", type=image_file, default="charuco_board.png", help="PNG to write")
    p.add_argument(
        "--squares", nargs=2, type=int_range(2, 200), default=[7, 5],
        metavar=("COLUMNS", "ROWS"), help="the board's squares",
    )  # fmt: skip
    p.add_argument("--square", type=float_range(1e-4, 10.0), default=0.04, help="square (m)")
    p.add_argument("--marker", type=float_range(1e-4, 10.0), default=0.03, help="marker (m)")
    p.add_argument("--dictionary", default="DICT_4X4_50", help="ArUco dictionary")
    p.add_argument("--dpi", type=int_range(50, 1200), default=300, help="print resolution")
    p.set_defaults(run=run_board)


def run_board(args: argparse.Namespace) -> int:
    """Write the board image; 0, or one line (exit 2) for a bad board."""
    import cv2

    from softarm.files.write import atomic_path
    from softarm.vision.calibration import charuco_board

    if args.marker >= args.square:
        raise InputError(f"--marker {args.marker:g} must be smaller than --square {args.square:g}")
    board = charuco_board(tuple(args.squares), args.square, args.marker, args.dictionary)
    px = round(1e3 * args.square / MM_PER_INCH * args.dpi)  # one square, in pixels
    margin = px // 2  # white around the board: the detector needs the outer squares' edges
    cols, rows = args.squares
    size = (cols * px + 2 * margin, rows * px + 2 * margin)
    if size[0] * size[1] > MAX_PIXELS:
        raise InputError(f"--dpi {args.dpi}: the board would be {size[0]}x{size[1]} px")
    image: Any = board.generateImage(size, marginSize=margin, borderBits=1)
    ok, png = cv2.imencode(".png", image)
    if not ok:
        raise InputError(f"{args.out}: OpenCV could not encode the board")
    with atomic_path(args.out, "board") as tmp:
        tmp.write_bytes(png.tobytes())
    width, height = (25.4 * s / args.dpi / 10 for s in size)
    print(
        f"board: {args.out}, {cols}x{rows} squares of {1e3 * args.square:g} mm, markers "
        f"{1e3 * args.marker:g} mm, {args.dictionary}; print at 100 % scale "
        f"({width:.1f} x {height:.1f} cm at {args.dpi} dpi) on a flat, rigid backing, "
        "measure a square, and give what you measure to `softarm camera calibrate "
        f"--squares {cols} {rows} --square M --marker M`"
    )
    return 0
