"""``softarm harvest``: harvest berries with the state machine, simulated or on hardware.

A progress bar with the ETA runs on stderr (when it is a terminal) and one line per berry
goes to stdout. SIGINT and SIGTERM stop the run cleanly: the arm is vented, the log gets
an ``interrupted`` record naming the signal, and the exit status is 130 or 143.
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softarm.commands._args import (
    add_quiet,
    config_file,
    image_file,
    int_range,
    non_negative_int,
    output_file,
)
from softarm.commands._dry_run import (
    add_dry_run_options,
    check_dry_run,
    dry_run_verdict,
    log_commands,
    replay_devices,
    replay_rounds,
)
from softarm.commands._looks import add_look
from softarm.commands._marker_bodies import MARKER_BODIES
from softarm.commands._plant import add_plant_options, plant_options
from softarm.commands._progress import Progress
from softarm.commands._run_info import (
    check_bag,
    hardware_header,
    sim_header,
    start_log,
    write_run_bag,
)
from softarm.commands._worlds import world_metavar, world_type
from softarm.errors import ConfigError, HardwareUnavailableError, ParameterError
from softarm.formatting import plural
from softarm.harvest_config import HarvestConfig
from softarm.sim.world import WorldName
from softarm.stops import drives_arm, records_late_stop, vents_on_stop

if TYPE_CHECKING:
    from softarm.config import Config
    from softarm.harvest.records.log import HarvestLog
    from softarm.harvest.records.report import HarvestReport
    from softarm.harvest.rigs.hardware.rig import HardwareRig
    from softarm.harvest.rigs.replay.devices import ReplayDevices
    from softarm.harvest.rigs.sim.rig import SimRig

#: Berries one command may ask for: as many as a simulated bush holds, a bush, not a field
#: (softarm.sim.bush.MAX_BERRIES; not imported here, it pulls in OpenCV).
MAX_BERRIES = 40


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``harvest`` subcommand."""
    p = sub.add_parser(
        "harvest",
        help="harvest berries: --sim for the simulated bush, --config for the hardware",
        description="Run the harvesting state machine (paper fig. 4) on a simulated bush "
        "(--sim) or on the hardware described by a TOML config (--config; write one with "
        "`softarm config init hw.toml`). One run policy on both: a berry lost from view is "
        "tried once more after the others, a safety fault ends the run. Exit status: 0 "
        "every berry done, 1 some berry faulted or was harvested OUTSIDE TOLERANCE (flagged "
        "on its line), 2 a usage or configuration error or no hardware, 130/143 stopped "
        "by SIGINT/SIGTERM (the arm is vented).",
    )
    mode = p.add_mutually_exclusive_group(required=True)
    mode.add_argument("--sim", action="store_true", help="simulated arm, cameras and bush")
    mode.add_argument("--config", type=config_file, help="hardware configuration (TOML)")
    p.add_argument(
        "--berries", type=int_range(1, MAX_BERRIES), default=5, help="berries to harvest"
    )
    p.add_argument(
        "--seed",
        type=non_negative_int,
        default=None,
        help="seed of the simulated bush and arm, and of the planner's restarts (both "
        "worlds; default 0, or the recording's with --dry-run)",
    )
    p.add_argument("--report", type=output_file, help="write the JSON report here")
    p.add_argument("--log", type=output_file, help="write the JSON-lines step log here")
    p.add_argument("--plot", type=image_file, help="save a plot of the run (--sim only)")
    p.add_argument(
        "--view",
        action="store_true",
        help="stream the run to the rerun viewer (--sim only; viz extra)",
    )
    p.add_argument(
        "--record", type=output_file, metavar="RUN.rrd",
        help="save a rerun recording of the run (--sim only; viz extra)",
    )  # fmt: skip
    p.add_argument(
        "--bag", type=output_file, metavar="RUN.mcap",
        help="write the run as a ROS 2 bag (rosbag2, MCAP; ros extra; docs/ros.md)",
    )  # fmt: skip
    p.add_argument(
        "--foxglove", nargs="?", const="127.0.0.1:8765", metavar="HOST:PORT",
        help="serve the run live to Foxglove on HOST:PORT (alone: 127.0.0.1:8765; "
        "foxglove extra; docs/ros.md)",
    )  # fmt: skip
    add_world_options(p)
    add_plant_options(p)
    add_dry_run_options(p)
    p.add_argument(
        "--gains",
        type=config_file,
        help="resolver gains: a TOML [gains] table of softarm.Gains keywords (`softarm tune` "
        "writes one); over the defaults with --sim, over the config's [gains] on hardware",
    )
    add_quiet(p)
    p.set_defaults(run=run)


def add_world_options(p: argparse.ArgumentParser) -> None:
    """The simulated world and what perceives it: ``--world``, ``--look``, ``--survey``,
    ``--detector``, ``--cane-source``, ``--marker-body``."""
    p.add_argument(
        "--world", type=world_type(*WorldName), metavar=world_metavar(*WorldName),
        default=WorldName.TAGS,
        help="--sim: 'tags', berries tagged and canes mapped (fast); 'bush', the rendered "
        "bush, berries and canes found by the cameras (render extra, MUJOCO_GL=egl); "
        "'row', the same bush inside a hedgerow in daylight (--look); "
        "--berries counts ripe and unripe together, 30%% unripe",
    )  # fmt: skip
    add_look(p)
    p.add_argument(
        "--survey", action=argparse.BooleanOptionalAction, default=None,
        help="--world bush: before the first berry, take C2 to three pairs of views of the "
        "bush and fit the canes with them (on by default: more of the canes mapped, "
        "docs/perception.md); --no-survey: C1's canes only",
    )  # fmt: skip
    p.add_argument(
        "--detector", choices=("colour", "net", "net+colour"), default=None,
        help="--world bush or row: the berry detector (default colour; docs/perception.md, "
        "'Which detector'); on the arm, [perception] detector",
    )  # fmt: skip
    p.add_argument(
        "--cane-source", choices=("colour", "net", "net+colour"), default=None,
        help="--world bush or row: where the cane pixels come from (default colour; "
        "docs/perception.md, 'Which cane pixels'); on the arm, [perception] canes",
    )  # fmt: skip
    p.add_argument(
        "--marker-body", choices=MARKER_BODIES, default=None,
        help="--sim: the marker body on the gripper that C1 tracks (default frustum; "
        "docs/hardware.md, 'The marker body'); on the arm, [calibration] marker_body",
    )  # fmt: skip


#: The share of unripe fruit on a rendered bush (``--world bush`` or ``row``).
BUSH_UNRIPE_FRACTION = 0.3


@drives_arm("harvest")
def run(args: argparse.Namespace) -> int:
    """Run the harvest; exit status (:func:`~softarm.harvest.runs.policy.exit_status`, the
    same on both rigs) 0 when every berry ended DONE within tolerance and nothing stopped
    the run, 1 otherwise, 2 when the hardware is absent, 128 + the signal number when
    stopped by SIGINT/SIGTERM."""
    if args.plot is not None and not args.sim:
        print("softarm harvest: error: argument --plot: works with --sim only", file=sys.stderr)
        return 2
    if (args.view or args.record is not None) and not args.sim:
        print("softarm harvest: error: --view/--record: work with --sim only", file=sys.stderr)
        return 2
    check_dry_run(args)
    check_render(args.sim and args.world.rendered)
    if args.survey is not None and not (args.sim and args.world.rendered):
        raise ParameterError(
            "--survey/--no-survey: for the rendered bush (--sim --world bush or row); "
            "on the arm, [perception] survey"
        )
    if args.look is not None and not (args.sim and args.world is WorldName.ROW):
        raise ParameterError("--look: for the rendered row (--sim --world row)")
    if args.detector is not None and not (args.sim and args.world.rendered):
        raise ParameterError(
            "--detector: for the rendered worlds; on the arm, [perception] detector"
        )
    if args.cane_source is not None and not (args.sim and args.world.rendered):
        raise ParameterError(
            "--cane-source: for the rendered worlds; on the arm, [perception] canes"
        )
    if args.marker_body is not None and not args.sim:
        raise ParameterError("--marker-body: for the simulator (--sim); on the arm, "
                             "[calibration] marker_body")  # fmt: skip
    check_bag(args.bag)
    check_view(args.view, args.record)
    check_foxglove(args.foxglove)
    configure_logging(args.quiet)
    options = plant_options(args)
    gains = _gains(args)
    if args.sim:
        args.seed = 0 if args.seed is None else args.seed
        if args.marker_body is not None:
            options.update(marker_body=args.marker_body)
        if args.world.rendered:
            options.update(world=args.world, unripe_fraction=BUSH_UNRIPE_FRACTION)
            options.update(survey=args.survey is not False, record_frames=args.record_frames)
            options.update(detector=args.detector or "colour")
            options.update(cane_source=args.cane_source or "colour")
        if args.world is WorldName.ROW:
            options.update(look=args.look)
        return run_sim(
            args.berries, args.seed, args.log, args.report, args.plot, args.quiet,
            gains=gains, view=args.view, record=args.record, bag=args.bag, args=args, **options,
        )  # fmt: skip
    return _run_hardware(args)


def check_render(bush: bool) -> None:
    """Before the banner and any output folder: the rendered bush (``bush``) needs MuJoCo
    and an offscreen OpenGL context (a one-line :class:`RenderUnavailableError` naming
    the fix, exit status 2, instead of MuJoCo's traceback on the first frame)."""
    if bush:
        from softarm.sim.render.gl_check import require_offscreen_gl

        require_offscreen_gl()


def check_foxglove(address: str | None) -> None:
    """Before any work: ``--foxglove`` needs foxglove-sdk, the ``foxglove`` extra, and a
    HOST:PORT (one line each)."""
    if address is not None:
        from softarm.viz.foxglove_live import parse_address, require_foxglove

        require_foxglove()
        parse_address(address)


def live_view(records: list[dict[str, Any]], address: str | None, vision: Any = None) -> Any:
    """The Foxglove server streaming the run log's ``records`` and the camera frames of
    ``vision`` (None without ``--foxglove``); its address printed for the user."""
    if address is None:
        return None
    from softarm.viz.foxglove_live import LiveView

    view = LiveView(records, address)
    if vision is not None:
        view.attach_cameras(vision)
    print(f"foxglove: live at {view.url} (Foxglove: Open connection)", flush=True)
    return view


def check_view(view: bool, record: Path | None) -> None:
    """Before any work (no banner, no log file): ``--view``/``--record`` need rerun-sdk,
    the ``viz`` extra (a one-line :class:`MissingDependencyError` naming it)."""
    if view or record is not None:
        from softarm.viz.rerun_sdk import require_rerun

        require_rerun()


def configure_logging(quiet: bool) -> None:
    """Vents and refused commands are logged by the safety layer
    (softarm.hardware.safety) at WARNING: show them tidily, above the progress bar."""
    logging.basicConfig(
        level=logging.ERROR if quiet else logging.WARNING, format="  [%(name)s] %(message)s"
    )


def run_sim(
    berries: int,
    seed: int,
    log_path: Path | None,
    report_path: Path | None,
    plot_path: Path | None,
    quiet: bool = False,
    gains: dict[str, Any] | None = None,
    view: bool = False,
    record: Path | None = None,
    bag: Path | None = None,
    args: argparse.Namespace | None = None,
    **options: Any,
) -> int:
    """The simulated harvest shared by ``harvest --sim`` and ``demo``; ``options`` are
    more ``SimRigOptions`` (``plant``, ``identified``: see ``commands/_plant.py``). The
    log and the report open with the run's header (``args``: the parsed command line);
    ``bag``: the run as a ROS 2 bag."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    check_view(view, record)  # demo's path too: before the banner and the log
    if not quiet:
        print(f"simulated harvest: {plural(berries, 'berry')}, seed {seed}", flush=True)
    rig_options = SimRigOptions(
        n_berries=berries, seed=seed, log_path=log_path, gains=gains or {}, **options
    )
    rig = build_sim_rig(rig_options)
    header = sim_header(rig, rig_options, args)
    start_log(rig.machine.log, header)
    # What C1 saw at IDLE, before the arm moved (the rendered bush only).
    seen = None
    if rig.scene is not None and plot_path is not None:
        from softarm.harvest.records.c1_picture import c1_picture

        seen = c1_picture(rig.scene, seed)
    viewer = _viewer(rig, view, record)
    live = live_view(rig.machine.log.records, getattr(args, "foxglove", None), rig.vision)
    try:
        try:
            with vents_on_stop(rig.machine.actuator.vent, rig.machine.log):
                report = _harvest(rig, berries, quiet)
        finally:
            if viewer is not None:
                viewer.close()  # the recording complete, even after a stop
            if live is not None:
                live.close()
        # The run's log is closed; a stop while the outputs are written is recorded in it.
        with records_late_stop(rig.machine.log):
            _sim_outputs(rig, report, report_path, bag, rig_options.record_frames, plot_path, seen)
            rig.close()  # the renderers freed here, not by finalizers at exit
    finally:
        rig.close()
    if log_path is not None:
        print(f"log: {log_path}")
    if record is not None:
        print(f"recording: {record}")
    from softarm.harvest.runs.policy import exit_status

    return exit_status(report, off_tolerance(report, rig.machine))


def _sim_outputs(
    rig: SimRig,
    report: HarvestReport,
    report_path: Path | None,
    bag: Path | None,
    frames: Any,
    plot_path: Path | None,
    seen: Any,
) -> None:
    """The summary line, then the report, the bag (with the recorded ``frames``) and the
    plot (with what C1 saw at IDLE, ``seen``) where asked for."""
    report.header = rig.machine.log.records[0]
    print(summary(report.to_dict(), Tolerance.of(getattr(rig.machine, "config", None))))
    if "rate" in report.extra:  # berries per hour and the time by stage (issue 40 item 4)
        from softarm.harvest.records.rate import rate_line

        print(rate_line(report.extra["rate"]))
    if report_path is not None:
        report.save(report_path)
        print(f"report: {report_path}")
    write_run_bag(rig.machine.log.records, bag, frames)
    if plot_path is not None:
        _plot(rig, report, plot_path)
        print(f"plot: {plot_path}")
        if seen is not None:
            seen_path = plot_path.with_name(plot_path.stem + "_c1.png")
            _save_image(seen, seen_path)
            print(f"what C1 saw: {seen_path}")


def _save_image(image: Any, path: Path) -> None:
    """Write an image through OpenCV's PNG encoder and the atomic writer."""
    import cv2

    from softarm.files.write import atomic_path

    ok, png = cv2.imencode(".png", image)
    if ok:
        with atomic_path(path, "plot") as tmp:
            tmp.write_bytes(png.tobytes())


def _harvest(rig: SimRig, n: int, quiet: bool) -> HarvestReport:
    seen: set[int] = set()
    last = time.monotonic()
    tol = Tolerance.of(getattr(rig.machine, "config", None))
    with Progress(n, "harvest", "berry", quiet) as bar:

        def on_berry(i: int, result: object) -> None:
            nonlocal last
            now = time.monotonic()
            retry = i in seen
            bar.line(line(i, n, result, now - last, retry, tol, tagged=rig.scene is None))
            last = now
            if not retry:
                seen.add(i)
                bar.advance()

        return rig.run(on_berry)


def _viewer(rig: SimRig, view: bool, record: Path | None) -> Any:
    """The rerun view of ``rig`` (softarm.viz.sim_view) for --view/--record, else None."""
    if not view and record is None:
        return None
    from softarm.viz.sim_view import attach

    return attach(rig, record=record, spawn=view)


def _plot(rig: SimRig, report: HarvestReport, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from softarm.harvest.rigs.sim.plots import plot_run

    plot_run(rig, report, path)


def missing_calibration(config: Config) -> list[str]:
    """Every calibration entry the hardware harvest needs and ``config`` lacks, so that
    one attempt reports them all."""
    cal = config.calibration
    missing = [name for name in ("T_C1_base", "T_C2_EE") if getattr(cal, name) is None]
    for name, cam in (("c1", cal.c1), ("c2", cal.c2)):
        if cam.file is None and cam.matrix is None:
            missing.append(f"c{name[1]}.matrix (or c{name[1]}.file)")
    return [f"calibration.{m}" for m in missing]


def _gains(args: argparse.Namespace) -> dict[str, Any] | None:
    """The ``[gains]`` of ``--gains FILE``, checked before the run (one-line errors)."""
    if getattr(args, "gains", None) is None:
        return None
    from softarm.sweep.gains_file import load_gains

    return load_gains(args.gains)


def _run_hardware(args: argparse.Namespace) -> int:
    from softarm.harvest.records.log import HarvestLog

    log = HarvestLog(args.log)  # first of all: a stop during set-up is recorded in it
    try:
        # Nothing is pressurised yet; a device opened so far is vented by its own close.
        with vents_on_stop(lambda reason: None, log):
            devices = replay_devices(args)  # --dry-run: the recording's, else the drivers
            if args.seed is None:
                args.seed = 0 if devices is None else devices.recorded_seed()
            if devices is not None:
                log_commands(devices, log)
            rig = _hardware_rig(args, log, devices)
    except HardwareUnavailableError as exc:
        log.close()
        print(
            f"softarm harvest: hardware not available: {exc}\n"
            "  Check the devices with `python examples/hardware_bringup.py`, "
            "or run `softarm harvest --sim` for the simulator.",
            file=sys.stderr,
        )
        return 2
    except Exception:
        log.close()
        raise
    berries = args.berries if devices is None else replay_rounds(devices)
    live = live_view(log.records, args.foxglove, getattr(rig, "vision", None))
    try:
        # The tags 10, 11, ... stuck to the berries (section IV-E), or the map's ripe
        # berries with markerless [perception].
        with vents_on_stop(rig.machine.actuator.vent, log):
            report = rig.run(berries)
        sent = None if devices is None else list(devices.commands)  # before the close
    finally:
        rig.close()  # vents and releases every device, whatever happened
        log.close()
        if live is not None:
            live.close()
    # The log is closed; a stop while the outputs are written is recorded in it.
    with records_late_stop(log):
        report.header = log.records[0]
        tol = Tolerance.of(getattr(rig.machine, "config", None))
        tagged = not getattr(rig, "markerless", False)
        for i, result in enumerate(report.berries):  # after the run: the lines a sim prints
            print(line(i, len(report.berries), result, None, tol=tol, tagged=tagged))
        print(summary(report.to_dict(), tol))
        from softarm.harvest.runs.policy import exit_status

        status = exit_status(report, off_tolerance(report, rig.machine))
        if devices is not None and sent is not None:
            status = max(status, dry_run_verdict(devices, sent, report))
        if args.report:
            report.save(args.report)
            print(f"report: {args.report}")
        write_run_bag(log.records, args.bag, args.frames)  # --dry-run: the frames replayed
    return status


def _hardware_config(args: argparse.Namespace) -> Config:
    """The hardware config with ``--gains`` over its ``[gains]``, its calibration complete."""
    from softarm.config import load_config

    config = load_config(args.config)
    if args.gains is not None:
        import dataclasses

        from softarm.config import GainsConfig

        merged = {**config.gains.values, **(_gains(args) or {})}
        config = dataclasses.replace(config, gains=GainsConfig(merged))
    missing = missing_calibration(config)
    if missing:
        raise ConfigError(
            f"{args.config}: set {', '.join(missing)} to harvest (see the comments that "
            "`softarm config init` writes)"
        )
    return config


def _hardware_rig(
    args: argparse.Namespace, log: HarvestLog, devices: ReplayDevices | None = None
) -> HardwareRig:
    """The hardware rig of ``args``, its header written to ``log`` first; ``devices``:
    the dry run's (default: the real drivers)."""
    from softarm.harvest.rigs.hardware.rig import build_hardware_rig
    from softarm.identified_plant import identified_from_config, load_identified

    config = _hardware_config(args)
    identified = (
        load_identified(args.identified)
        if getattr(args, "identified", None) is not None
        else identified_from_config(config, args.config)
    )
    calibration = plant_options(args).get("calibration")  # --model: the arm and its gains
    start_log(log, hardware_header(config, args))
    return build_hardware_rig(
        config, log=log, identified=identified, calibration=calibration, devices=devices,
        seed=args.seed,
    )  # fmt: skip


@dataclass(frozen=True)
class Tolerance:
    """What a grasp must reach to count as within tolerance: fine positioning's position
    tolerance (mm) and the pointing tolerance (deg), ``[harvest]`` ``fine_tolerance`` and
    ``angle_tolerance_deg``."""

    position_mm: float = 1e3 * HarvestConfig.fine_tolerance
    angle_deg: float = HarvestConfig.angle_tolerance_deg

    @classmethod
    def of(cls, config: HarvestConfig | None) -> Tolerance:
        """The tolerance of a rig's ``[harvest]`` settings (None: the defaults)."""
        if not isinstance(config, HarvestConfig):
            return cls()
        return cls(1e3 * config.fine_tolerance, config.angle_tolerance_deg)


def _number(v: Any) -> float | None:
    return None if v is None or not math.isfinite(v) else float(v)


def grasp_errors(d: dict[str, Any]) -> tuple[float | None, float | None]:
    """A berry's (position mm, orientation deg) errors: against ground truth where known
    (simulation), else as measured; None where not recorded."""
    pos = _number(d.get("true_position_error_mm"))
    if pos is None:
        pos = _number(d.get("position_error_mm"))
    ang = _number(d.get("true_orientation_error_deg"))
    if ang is None:
        ang = _number(d.get("orientation_error_deg"))
    return pos, ang


def outside(d: dict[str, Any], tol: Tolerance) -> list[str]:
    """Why a harvested berry's grasp is outside tolerance (empty if it is not)."""
    pos, ang = grasp_errors(d)
    why = []
    if pos is not None and pos > tol.position_mm:
        why.append(f"position > {tol.position_mm:g} mm")
    if ang is not None and ang > tol.angle_deg:
        why.append(f"orientation > {tol.angle_deg:g} deg")
    return why


def off_tolerance(report: HarvestReport, machine: Any) -> bool:
    """Whether a berry was harvested outside the tolerance of ``machine``'s ``[harvest]``
    (such a run exits 1, as one with a fault does)."""
    tol = Tolerance.of(getattr(machine, "config", None))
    return any(outside(b, tol) for b in report.to_dict()["berries"] if b["harvested"])


def line(
    i: int,
    n: int,
    r: Any,
    wall: float | None,
    retry: bool = False,
    tol: Tolerance | None = None,
    *,
    tagged: bool = True,
) -> str:
    """One line per berry: its outcome, its position and orientation errors (flagged
    when outside ``tol``), and its own simulated and wall time (``wall`` None: on the
    arm or in a dry run, the run's own time alone). A berry is named by its
    tag, or (not ``tagged``: the rendered bush) by its number in the bush map, the
    number of the C1 picture."""
    d = r.to_dict()
    pos, ang = grasp_errors(d)
    what = "harvested" if d["harvested"] else (d["fault"] or "skipped (unripe)")
    pos_s = f"{pos:.2f} mm" if pos is not None else "-"
    ang_s = f"{ang:.1f} deg" if ang is not None else "-"
    tag = f"tag {d['tag_id']}" if tagged else f"map #{d['tag_id']}"
    tag += ", retry" if retry else ""
    why = outside(d, tol or Tolerance()) if d["harvested"] else []
    flag = f"  OUTSIDE TOLERANCE ({', '.join(why)})" if why else ""
    took = f"took {d['duration_s']:.1f} s"
    took += f" simulated, {wall:.1f} s wall" if wall is not None else ""
    return f"berry {i + 1}/{n} ({tag}): {what:<16} error {pos_s:>9}, {ang_s:>8}  {took}{flag}"


def summary(d: dict[str, Any], tol: Tolerance | None = None) -> str:
    """The run summary line: mean position and orientation errors of the harvested
    berries, and how many were grasped outside ``tol``."""
    tol = tol or Tolerance()
    harvested = [b for b in d["berries"] if b["harvested"]]
    errs = [grasp_errors(b) for b in harvested]
    pos = [p for p, _ in errs if p is not None]
    ang = [a for _, a in errs if a is not None]
    mean = f"{sum(pos) / len(pos):.2f} mm" if pos else "-"
    # The simulation knows the true errors; the arm and a dry run, the cameras' alone.
    true = any(b.get("true_position_error_mm") is not None for b in harvested)
    source = "(true, from the simulation)" if true else "(as the cameras measured it)"
    mean_ang = f"{sum(ang) / len(ang):.1f} deg" if ang else "-"
    extra = ""
    off = sum(1 for b in harvested if outside(b, tol))
    if off:
        extra += f", {plural(off, 'berry')} OUTSIDE TOLERANCE"
    if "min_branch_gap_m" in d:
        gap = d["min_branch_gap_m"]  # None: the arm never moved (no ripe berry in the map)
        gap_s = "-" if gap is None else f"{1e3 * gap:.1f} mm"
        extra += f", min cane gap {gap_s}, {d['branch_contact_steps']} contact steps"
    if d.get("sim_time_s") is not None:
        extra += f", {d['sim_time_s']:.1f} s simulated"
    if "ripe_in_reach" in d:  # the rendered bush: what the bush held, not only the map
        extra += f"; {d['ripe_harvested']}/{d['ripe_in_reach']} ripe berries picked"
        if d.get("unripe_left") is not None:
            extra += f", {plural(d['unripe_left'], 'unripe berry')} left on the bush"
    return (
        f"harvested {d['harvested']}/{d['attempted']} ({100 * d['success_rate']:.0f} %), "
        f"mean fine-positioning error {mean}, {mean_ang} {source}{extra}"
    )
