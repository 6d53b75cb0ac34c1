"""``softarm harvest``: harvest berries with the state machine, simulated or on hardware."""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

from softarm.errors import HardwareUnavailableError


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``harvest`` subcommand."""
    p = sub.add_parser(
        "harvest",
        help="harvest berries: --sim for the simulated bush, --config for the hardware",
        description="Run the harvesting state machine (paper fig. 4) on a simulated bush "
        "(--sim) or on the hardware described by a TOML config (--config).",
    )
    mode = p.add_mutually_exclusive_group(required=True)
    mode.add_argument("--sim", action="store_true", help="simulated arm, cameras and bush")
    mode.add_argument("--config", type=Path, help="hardware configuration (TOML)")
    p.add_argument("--berries", type=int, default=5, help="berries to harvest (default 5)")
    p.add_argument("--seed", type=int, default=0, help="seed of the simulated bush and arm")
    p.add_argument("--report", type=Path, help="write the JSON report here")
    p.add_argument("--log", type=Path, help="write the JSON-lines step log here")
    p.add_argument("--plot", type=Path, help="save a plot of the run (simulation only)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run the harvest; exit status 0 when every berry ended DONE, 1 otherwise, 2 when
    the hardware is absent."""
    # Vents are logged by the safety layer (softarm.hardware.safety): show them tidily.
    logging.basicConfig(level=logging.WARNING, format="  [%(name)s] %(message)s")
    if args.sim:
        return _run_sim(args)
    return _run_hardware(args)


def _run_sim(args: argparse.Namespace) -> int:
    from softarm.harvest.sim_rig import SimRigOptions, build_sim_rig

    rig = build_sim_rig(SimRigOptions(n_berries=args.berries, seed=args.seed, log_path=args.log))
    start = time.monotonic()

    def progress(i: int, r: object) -> None:
        print(_line(i, args.berries, r, time.monotonic() - start), flush=True)

    report = rig.run(progress)
    print(_summary(report.to_dict()))
    if args.report:
        report.save(args.report)
        print(f"report: {args.report}")
    if args.plot:
        from softarm.harvest.plots import plot_run

        plot_run(rig, report, args.plot)
        print(f"plot: {args.plot}")
    return 0 if all(b.final_state.value == "done" for b in report.berries) else 1


def _run_hardware(args: argparse.Namespace) -> int:
    from softarm.config import load_config
    from softarm.harvest.hw_rig import build_hardware_rig
    from softarm.harvest.interfaces import BerryTarget
    from softarm.harvest.log import HarvestLog

    config = load_config(args.config)
    try:
        rig = build_hardware_rig(config, log=HarvestLog(args.log))
    except HardwareUnavailableError as exc:
        print(
            f"softarm harvest: hardware not available: {exc}\n"
            "  Check the devices with `python examples/hardware_bringup.py`, "
            "or run `softarm harvest --sim` for the simulator.",
            file=sys.stderr,
        )
        return 2
    try:
        # On hardware the berries are the tags 10, 11, ... stuck to them (section IV-E).
        report = rig.machine.run([BerryTarget(10 + i) for i in range(args.berries)])
    finally:
        rig.close()
    print(_summary(report.to_dict()))
    if args.report:
        report.save(args.report)
    return 0 if report.stopped is None else 1


def _line(i: int, n: int, r: object, wall: float) -> str:
    """One progress line per berry."""
    d = r.to_dict()  # type: ignore[attr-defined]
    err = d.get("true_position_error_mm") or d.get("position_error_mm")
    what = "harvested" if d["harvested"] else (d["fault"] or "skipped (unripe)")
    err_s = f"{err:.2f} mm" if err is not None else "-"
    return (
        f"berry {i + 1}/{n} (tag {d['tag_id']}): {what:<16} error {err_s:>9}  "
        f"{d['duration_s']:5.1f} s simulated, {wall:5.1f} s wall"
    )


def _summary(d: dict) -> str:
    """The run summary line."""
    errs = [
        b.get("true_position_error_mm") or b["position_error_mm"]
        for b in d["berries"]
        if b["harvested"]
    ]
    mean = f"{sum(errs) / len(errs):.2f} mm" if errs else "-"
    extra = ""
    if "min_branch_gap_m" in d:
        extra = (
            f", min cane gap {1e3 * d['min_branch_gap_m']:.1f} mm, "
            f"{d['branch_contact_steps']} contact steps"
        )
    return (
        f"harvested {d['harvested']}/{d['attempted']} ({100 * d['success_rate']:.0f} %), "
        f"mean fine-positioning error {mean}{extra}"
    )
