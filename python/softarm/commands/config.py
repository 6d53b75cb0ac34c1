"""softarm config: write a commented hardware configuration, or check one.

softarm config init hw.toml      # the template: fill in the calibration, then
softarm config check hw.toml     # says what is still missing before a harvest
softarm harvest --config hw.toml
"""

from __future__ import annotations

import argparse
import functools
import sys
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

from softarm.commands._args import RawDefaultsFormatter, config_file, output_file
from softarm.errors import ConfigError, SoftarmError
from softarm.files import write_text

if TYPE_CHECKING:
    from softarm.config import Config

#: Replaces the shipped file's [calibration] tables: every entry the hardware harvest
#: needs, commented out with a placeholder of the right shape and where its value comes
#: from. Uncommenting the placeholders gives a file `softarm harvest` accepts as is.
CALIBRATION = """\
[calibration]
# Both poses are 4x4 (rotation block and translation in m). Measure them, replace the
# identity placeholders and uncomment the two lines:
#  - T_C1_base is the arm's base in the eye-to-hand camera C1, from the base tag (eq. 22,
#    softarm.vision.BaseRegistration);
#  - T_C2_EE is the end effector in the eye-in-hand camera C2, from the hand-eye
#    calibration (eq. 21).
# T_C1_base = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
# T_C2_EE = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
# The marker cube in the end-effector frame (eq. 22; rotation block and translation in m),
# and the side (m) of the berry tags: measure your build (these are the defaults).
T_EE_cube = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -0.05], [0, 0, 0, 1]]
berry_tag = 0.012
# The body carrying the tags C1 tracks: "cube" (the paper's) or "frustum" (docs/hardware.md,
# "The marker body"), and its tags' side (m).
marker_body = "cube"
marker_length = 0.08

[calibration.c1]  # eye-to-hand camera (a ZED2 in the paper)
source = 0  # OpenCV device index, or a video file or stream URL
# Intrinsics, from a camera calibration: a file written by softarm.vision.CameraModel.save
# (file = "c1.json") or inline. Replace the placeholders (a 1280x720 camera with f = 900 px
# and no distortion) and uncomment; distortion is OpenCV's k1, k2, p1, p2, k3.
# matrix = [[900.0, 0.0, 640.0], [0.0, 900.0, 360.0], [0.0, 0.0, 1.0]]
# distortion = [0.0, 0.0, 0.0, 0.0, 0.0]

[calibration.c2]  # eye-in-hand camera (a DEPSTECH endoscope in the paper)
source = 1
# matrix = [[600.0, 0.0, 320.0], [0.0, 600.0, 240.0], [0.0, 0.0, 1.0]]
# distortion = [0.0, 0.0, 0.0, 0.0, 0.0]

"""

#: Appended to the template: the markerless harvest's stereo source, commented out (the
#: harvest finds tagged berries with C1 alone without it).
PERCEPTION = """\

# [perception]  # C1 as a stereo camera: berries without tags, canes fitted from depth
# stereo = "zed2"  # one side-by-side USB video device (a ZED2 without its SDK), or "pair"
# device = 0  # the ZED2's OpenCV device index or a path; a "pair" takes left and right
# calibration = "stereo.yml"  # from `softarm camera calibrate`, next to this file
# berries = "markerless"  # or "tags"
# survey = true  # false: no C2 views of the bush before the first berry (C1's canes only)
# detector = "colour"  # the berry detector: "colour", "net" or "net+colour" (docs/perception.md)
# canes = "colour"  # the cane pixels' source: "colour", "net" or "net+colour" (docs/perception.md)
"""

HEADER = """\
# softarm hardware configuration, written by `softarm config init`.
# 1. Fill in [calibration] below (the poses and both cameras' intrinsics).
# 2. Check the channel names, the serial port and the pressure limits for your rig, and
#    the marker cube's mount and berry tag size in [calibration]; tune in [harvest].
# 3. `softarm config check THIS_FILE`, then `softarm harvest --config THIS_FILE`.
# The arm geometry is the blackberry arm of the redundancy paper, as shipped:
"""


def template() -> str:
    """The commented template: the shipped blackberry configuration with the
    calibration entries to fill in."""
    shipped = resources.files("softarm.data").joinpath("blackberry.toml").read_text("utf-8")
    start, end = shipped.index("\n[calibration]") + 1, shipped.index("\n[channels]") + 1
    return HEADER + shipped[:start] + CALIBRATION + shipped[end:] + PERCEPTION


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``config init`` and ``config check``."""
    p = sub.add_parser(
        "config",
        help="write a commented hardware configuration (init) or check one (check)",
        description=__doc__,
        formatter_class=RawDefaultsFormatter,
    )
    actions = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    init = actions.add_parser("init", help="write the commented template")
    init.add_argument("path", type=output_file, help="the TOML file to write")
    init.add_argument("--force", action="store_true", help="overwrite an existing file")
    init.set_defaults(run=run_init)
    check = actions.add_parser(
        "check",
        help="validate a configuration for a harvest, opening every file it names",
    )
    check.add_argument("path", type=config_file, help="the TOML file to check")
    check.set_defaults(run=run_check)


def run_init(args: argparse.Namespace) -> int:
    """Write the template (refusing to overwrite without --force)."""
    if args.path.exists() and not args.force:
        raise ConfigError(f"{args.path} exists; pass --force to overwrite it")
    write_text(args.path, template(), "config file")
    print(f"wrote {args.path}: fill in [calibration], then `softarm config check {args.path}`")
    return 0


def run_check(args: argparse.Namespace) -> int:
    """Load and validate, then open and parse every file the config names; exit 0 when
    a hardware harvest can start from it, 1 when the calibration is incomplete (each
    missing entry is named), 2 when it is invalid (each problem on its own line)."""
    from softarm.commands.harvest import missing_calibration
    from softarm.config import load_config

    config = load_config(args.path)
    problems = file_problems(config, args.path)
    for problem in problems:
        print(f"softarm config: error: {args.path}: {problem}", file=sys.stderr)
    if problems:
        return 2
    ch = config.channels
    print(
        f"{args.path}: valid; {len(config.arm.sections)} sections, {len(ch.names)} channels, "
        f"p_max {ch.p_max:g} psi, serial {config.serial.port}"
    )
    missing = missing_calibration(config)
    if missing:
        print(f"not ready to harvest: set {', '.join(missing)}")
        return 1
    print(f"ready: softarm harvest --config {args.path}")
    return 0


def file_problems(config: Config, path: Path) -> list[str]:
    """One line per file the config names that cannot be opened or parsed, and per
    inline value that the harvest would refuse: both cameras' intrinsics, the gains,
    the identified plant (``[plant_model]``) and the stereo calibration
    (``[perception]``)."""
    from softarm._core import Gains
    from softarm.perception_config import check_perception
    from softarm.vision.camera_model import camera_from_config

    checks: list[Callable[[], object]] = [
        functools.partial(camera_from_config, cam, name)
        for name, cam in (("c1", config.calibration.c1), ("c2", config.calibration.c2))
        if cam.file is not None or cam.matrix is not None
    ]
    checks.append(lambda: Gains(**config.gains.values))
    checks.append(lambda: _plant_model(config, path))
    checks.append(functools.partial(check_perception, config.perception))
    return [p for p in map(_problem, checks) if p is not None]


def _plant_model(config: Config, path: Path) -> object:
    """The identified plant of ``[plant_model]``; a bad file's error names the key."""
    from softarm.identified_plant import identified_from_config

    try:
        return identified_from_config(config, path)
    except ConfigError as exc:
        key = "plant_model.file: " if config.plant_model and config.plant_model.file else ""
        raise ConfigError(f"{key}{exc}") from None


def _problem(check: Callable[[], object]) -> str | None:
    """The one-line message of the error ``check`` raises, or None."""
    try:
        check()
    except (SoftarmError, ValueError, TypeError) as exc:
        return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return None
