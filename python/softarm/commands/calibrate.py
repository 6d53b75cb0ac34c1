"""``softarm calibrate``: fit the arm model to measured poses and write ``model.toml``."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from softarm.commands._args import add_quiet, config_file, int_range, non_negative_int, output_file
from softarm.errors import HardwareUnavailableError
from softarm.stops import drives_arm

if TYPE_CHECKING:
    from softarm.calibration import Calibration

Progress = Callable[[int, Any], None]

#: Where the fitted model is written without --out (as identify's id.json). A string, so
#: that argparse checks it with output_file as it does a typed --out.
OUT = "model.toml"


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``calibrate`` subcommand."""
    p = sub.add_parser(
        "calibrate",
        help="fit the arm's geometry and actuator gains to measured poses (model.toml)",
        description="Drive the arm through a safe excitation set (at most 100 poses inside "
        "the limits), measure the end-effector pose at each, and fit per-section radius, "
        "rest length, plate offset and twist and per-actuator gains. The simulated plant "
        "with --sim (the one `softarm harvest --sim --seed S` runs on), the hardware with "
        "--config. Use the result with `softarm harvest --model model.toml`.",
    )
    mode = p.add_mutually_exclusive_group(required=True)
    mode.add_argument("--sim", action="store_true", help="the simulated plant")
    # Every argument, the output included, is checked while the command line is parsed,
    # before a pose is measured: a fit must not be lost to a bad --out after it has run.
    mode.add_argument("--config", type=config_file, help="hardware configuration (TOML)")
    p.add_argument("--plant", type=config_file, help="simulated plant parameters ([plant] TOML)")
    p.add_argument(
        "--seed", type=non_negative_int, default=0, help="seed of the simulated plant (as harvest)"
    )
    p.add_argument(
        "--poses", type=int_range(22, 100), default=80, help="excitation poses (21 parameters)"
    )
    p.add_argument("--out", type=output_file, default=OUT, help="the fitted model (TOML) to write")
    p.add_argument(
        "--bias",
        action="store_true",
        help="also fit a constant bending bias per section (the gravity-aware term)",
    )
    add_quiet(p)
    p.set_defaults(run=run)


@drives_arm("calibrate")
def run(args: argparse.Namespace) -> int:
    """Calibrate; exit status 0 on a converged fit, 1 if the solver did not converge, 2
    on bad input or absent hardware."""
    from softarm.errors import ParameterError

    if args.plant is not None and not args.sim:
        raise ParameterError("--plant: only with --sim")
    start = time.monotonic()

    def progress(k: int, _pose: object) -> None:
        if not args.quiet and ((k + 1) % 10 == 0 or k + 1 == args.poses):
            print(
                f"pose {k + 1}/{args.poses} measured, {time.monotonic() - start:5.1f} s wall",
                file=sys.stderr,
                flush=True,
            )

    cal = _sim(args, progress) if args.sim else _hardware(args, progress)
    if cal is None:
        return 2
    cal.save(args.out)
    print(f"fit: {cal.fit}")
    gains = ", ".join(f"{g:.3f}" for g in cal.actuator_gain)
    print(f"actuator gains: [{gains}]")
    print(f"model: {args.out}  ({'converged' if cal.converged else 'NOT converged'})")
    return 0 if cal.converged else 1


def _sim(args: argparse.Namespace, progress: Progress) -> Calibration:
    from softarm._core import SoftArm
    from softarm.calibration.sim import build_plant, calibrate_plant
    from softarm.sim.arm import PlantConfig

    if args.plant is not None:
        from softarm.sim.plant_file import load_plant_file

        config = load_plant_file(args.plant)
    else:
        config = PlantConfig()
    nominal = SoftArm.blackberry()
    # The harvest rig draws its plant from seed + 1000 (softarm.harvest.rigs.sim.rig).
    plant = build_plant(nominal, config, args.seed + 1000)
    cal, _, _ = calibrate_plant(
        plant, config, nominal, n_poses=args.poses, seed=args.seed, on_pose=progress,
        bias=args.bias,
    )  # fmt: skip
    return cal


def _hardware(args: argparse.Namespace, progress: Progress) -> Calibration | None:
    from softarm._core import Section, SoftArm
    from softarm.calibration import calibrate
    from softarm.calibration.collect import collect, paced_for
    from softarm.calibration.excitation import excitation_set
    from softarm.config import load_config
    from softarm.harvest.rigs.hardware.rig import build_hardware_rig
    from softarm.identified_plant import identified_from_config

    config = load_config(args.config)
    nominal = SoftArm([Section(**vars(s)) for s in config.arm.sections])
    # Holds paced for the identified plant ([plant_model]) when there is one.
    identified = identified_from_config(config, args.config)
    pace = {} if identified is None else paced_for(identified.lag_s, max(identified.play_m))
    try:
        rig = build_hardware_rig(config)
    except HardwareUnavailableError as exc:
        print(f"softarm calibrate: hardware not available: {exc}", file=sys.stderr)
        return None
    try:
        m = rig.machine
        c, p = collect(
            excitation_set(nominal, args.poses, seed=args.seed),
            m.actuator.send,
            m.clock.sleep,
            lambda: m.vision.track(m.clock.now()),  # type: ignore[attr-defined]
            on_pose=progress,
            **pace,
        )
    finally:
        rig.close()  # vents the arm
    return calibrate(nominal, c, p, bias=args.bias)
