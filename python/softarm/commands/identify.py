"""``softarm identify``: measure the plant's lag, dead time, elongation per psi and
hysteresis per channel (docs/identification.md) and write ``id.json``.

The arm runs step, ramp and random-pose tests through the safety layer for at most two
minutes of arm time (simulated time with ``--sim``), then vents. ``--sim`` identifies the
plant ``softarm harvest --sim --seed S [--plant FILE]`` runs on.
"""

from __future__ import annotations

import argparse
import logging
import sys
from typing import TYPE_CHECKING

from softarm.commands._args import add_quiet, config_file, non_negative_int, output_file
from softarm.errors import HardwareUnavailableError
from softarm.stops import drives_arm

if TYPE_CHECKING:
    from softarm.commands._progress import Progress
    from softarm.identification import IdentifiedPlant
    from softarm.identification.record import Progress as OnProgress

#: Where the identified plant is written without --out (as calibrate's model.toml).
OUT = "id.json"
#: The longest excitation (s of arm time) the command runs.
MAX_BUDGET_S = 120.0


def _budget(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not 30.0 <= value <= MAX_BUDGET_S:
        raise argparse.ArgumentTypeError(
            f"must be in [30, {MAX_BUDGET_S:g}] s of arm time, got {text!r}"
        )
    return value


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``identify`` subcommand."""
    p = sub.add_parser(
        "identify",
        help="identify the plant's lag, gains and hysteresis per channel (id.json)",
        description="Step, ramp and random-pose tests through the safety layer (at most 2 "
        "minutes of arm time, never outside the limits), then a fit of each channel's "
        "regulator time constant and dead time (pressure readings) and elongation per psi "
        "and hysteresis (tracked poses, geometry fitted alongside). --sim runs on the "
        "simulated plant of `softarm harvest --sim --seed S`, --config on the hardware. "
        "Exit status: 0 done, 1 done but an estimate is more uncertain than its tolerance "
        "(id.json marks it), 2 a usage, configuration or hardware error, 130/143 stopped "
        "by SIGINT/SIGTERM (the arm is vented).",
    )
    mode = p.add_mutually_exclusive_group(required=True)
    mode.add_argument("--sim", action="store_true", help="the simulated plant")
    mode.add_argument("--config", type=config_file, help="hardware configuration (TOML)")
    p.add_argument("--plant", type=config_file, help="simulated plant ([plant] TOML, --sim)")
    p.add_argument(
        "--seed", type=non_negative_int, default=0, help="seed of the simulated plant (as harvest)"
    )
    # A string default goes through output_file as a typed one does: checked at parse time.
    p.add_argument(
        "--out", type=output_file, default=OUT, help="the identified plant (JSON) to write"
    )
    p.add_argument(
        "--budget", type=_budget, default=MAX_BUDGET_S, help="arm time of the excitation (s)"
    )
    add_quiet(p)
    p.set_defaults(run=run)


@drives_arm("identify")
def run(args: argparse.Namespace) -> int:
    """Identify and save; 0 on success, 1 when an estimate is beyond its tolerance, 2 on
    bad input or absent hardware."""
    from softarm.errors import ParameterError

    if args.plant is not None and not args.sim:
        raise ParameterError("--plant: works with --sim only (the hardware is its own plant)")
    logging.basicConfig(
        level=logging.ERROR if args.quiet else logging.WARNING, format="  [%(name)s] %(message)s"
    )
    plant = _run_sim(args) if args.sim else _run_hardware(args)
    if plant is None:
        return 2
    plant.save(args.out)
    _print(plant, args.quiet)
    print(f"saved {args.out}")
    poor = plant.metadata.get("poor_estimates") or []
    if poor:
        print(
            f"softarm identify: warning: {len(poor)} estimates beyond their tolerance "
            f"(marked in {args.out}): {'; '.join(poor)}",
            file=sys.stderr,
        )
        return 1
    return 0


def _progress(quiet: bool, budget: float) -> Progress:
    from softarm.commands._progress import Progress

    return Progress(round(budget), "identify", "s arm time", quiet)


def _run_sim(args: argparse.Namespace) -> IdentifiedPlant:
    from softarm.identification import Design, SimIdentificationRig, identify
    from softarm.sim.arm import PlantConfig
    from softarm.sim.plant_file import load_plant_file

    config = load_plant_file(args.plant) if args.plant is not None else PlantConfig()
    rig = SimIdentificationRig(config, seed=args.seed)
    design = Design(n=rig.bank.channels, budget_s=args.budget, seed=args.seed)
    meta = {
        "source": "sim",
        "seed": args.seed,
        "plant_file": str(args.plant) if args.plant else None,
        "plant": {k: getattr(config, k) for k in config.__dataclass_fields__},
        "sim_truth": rig.truth(),
    }
    with _progress(args.quiet, args.budget) as bar:
        try:
            return identify(rig, rig.model, design, _advance(bar), meta)
        finally:
            rig.close()


def _run_hardware(args: argparse.Namespace) -> IdentifiedPlant | None:
    from softarm._core import Section, SoftArm
    from softarm.config import load_config
    from softarm.identification import Design, identify
    from softarm.identification.hardware import HardwareIdentificationRig

    config = load_config(args.config)
    arm = SoftArm([Section(**vars(s)) for s in config.arm.sections])
    ch = config.channels
    # Stay inside both the safety limit and the arm's elongation limits, with margin.
    top = min(ch.p_max, min(s.upper for s in config.arm.sections) / ch.metres_per_psi)
    design = Design(
        n=len(ch.names), lo=0.12 * top, hi=0.88 * top, base=0.5 * top, amplitude=0.35 * top,
        ramp_rate=min(40.0, 0.4 * ch.max_rate_psi_per_s), budget_s=args.budget,
        seed=args.seed,
    )  # fmt: skip
    try:
        rig = HardwareIdentificationRig(config)
    except HardwareUnavailableError as exc:
        print(
            f"softarm identify: hardware not available: {exc}\n"
            "  Check the devices with `python examples/hardware_bringup.py`, "
            "or run `softarm identify --sim` for the simulator.",
            file=sys.stderr,
        )
        return None
    meta = {"source": "hardware", "config": str(args.config)}
    with _progress(args.quiet, args.budget) as bar:
        try:
            return identify(rig, arm, design, _advance(bar), meta)
        finally:
            rig.close()


def _advance(bar: Progress) -> OnProgress:
    done = [0]

    def progress(t: float, budget: float, what: str) -> None:
        step = int(t) - done[0]
        if step > 0:
            bar.advance(step)
            done[0] += step
        bar.describe(what)

    return progress


def _print(plant: IdentifiedPlant, quiet: bool) -> None:
    truth = plant.metadata.get("sim_truth")
    print(
        f"identified {plant.n_channels} channels from {plant.metadata['arm_time_s']:.1f} s "
        f"of arm time; pose residual {plant.metadata['pose_rms_mm']:.3f} mm RMS"
    )
    if quiet:
        return
    head = f"{'ch':>3} {'tau s':>8} {'dead s':>8} {'um/psi':>8} {'hyst psi':>9}"
    print(head + ("   (error vs the simulated plant: tau, m/psi, hysteresis)" if truth else ""))
    for i in range(plant.n_channels):
        row = (
            f"{i:>3} {plant.tau_s[i]:8.4f} {plant.dead_time_s[i]:8.4f} "
            f"{plant.metres_per_psi[i] * 1e6:8.3f} {plant.hysteresis_psi[i]:9.3f}"
        )
        if truth:
            errs = [
                100 * (getattr(plant, k)[i] / truth[k][i] - 1) if truth[k][i] > 0 else float("nan")
                for k in ("tau_s", "metres_per_psi", "hysteresis_psi")
            ]
            row += "   " + "  ".join(f"{e:+6.2f} %" for e in errs)
        print(row)
