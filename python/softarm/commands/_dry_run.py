"""``softarm harvest``'s dry run of the hardware path: ``--record-frames DIR`` with
``--sim --world bush`` (or ``row``) records, ``--config DIR/hw.toml --frames DIR --dry-run``
replays (:mod:`softarm.harvest.rigs.replay.dry_run`, :mod:`softarm.harvest.rigs.replay.devices`)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softarm.commands._args import output_dir
from softarm.errors import ParameterError

if TYPE_CHECKING:
    from softarm.harvest.records.log import HarvestLog
    from softarm.harvest.records.report import HarvestReport
    from softarm.harvest.rigs.replay.devices import ReplayDevices

__all__ = [
    "add_dry_run_options",
    "check_dry_run",
    "dry_run_verdict",
    "log_commands",
    "replay_devices",
    "replay_rounds",
]

#: A replayed pressure command may differ from the recorded one by this much (psi):
#: the same images in must give the same commands out.
SAME_PSI = 1e-9


def add_dry_run_options(p: argparse.ArgumentParser) -> None:
    """Add ``--record-frames``, ``--frames`` and ``--dry-run`` to ``p``."""
    p.add_argument(
        "--record-frames", type=output_dir, metavar="DIR",
        help="--sim --world bush or row: record every camera frame (as the camera model "
        "delivers it, in the row), ripeness reading and "
        "pressure command in DIR, with DIR/hw.toml, the rig as a hardware configuration "
        "(the dry run's input). Recorded into a fresh folder beside DIR, moved into place "
        "when the run ends: DIR must be new, empty or an earlier recording (it holds "
        "frames.json), which is replaced whole; a stopped run leaves DIR as it was",
    )  # fmt: skip
    p.add_argument(
        "--frames", type=Path, metavar="DIR",
        help="with --config and --dry-run: the cameras read the frames recorded in DIR",
    )  # fmt: skip
    p.add_argument(
        "--dry-run", action="store_true",
        help="with --config and --frames: run the hardware path on recorded frames and "
        "readings, the pressure outputs, gripper and sensor faked; compares the commands "
        "with the recorded ones (nothing is driven)",
    )  # fmt: skip


def check_dry_run(args: argparse.Namespace) -> None:
    """Refuse the dry-run options outside their mode.

    Raises:
        ParameterError: the option and what it needs, named.
    """
    if args.record_frames is not None and not (args.sim and args.world.rendered):
        raise ParameterError(
            "--record-frames: records the rendered worlds (--sim --world bush or row)"
        )
    if args.dry_run != (args.frames is not None):
        raise ParameterError("--dry-run and --frames DIR: give both (with --config)")
    if args.dry_run and args.sim:
        raise ParameterError("--dry-run: replays the hardware path (--config), not --sim")


def replay_devices(args: argparse.Namespace) -> ReplayDevices | None:
    """The recording's devices for ``--dry-run`` (the folder checked: every frame
    present and in order), else None.

    Raises:
        ConfigError: the folder or its index is missing or broken (named).
    """
    if not args.dry_run:
        return None
    from softarm.harvest.records.frame_files import FrameFolder
    from softarm.harvest.rigs.replay.devices import ReplayDevices

    return ReplayDevices(FrameFolder(args.frames))


def replay_rounds(devices: ReplayDevices) -> int:
    """The looks the markerless loop may take: as many as the recording's stereo pairs
    (the first look and the cane fit took two of them)."""
    return max(1, len(devices.folder.entries.get("c1_left", [])) - 2)


def log_commands(devices: ReplayDevices, log: HarvestLog) -> None:
    """Write each command the dry run would have sent into ``log`` as it is sent. The
    rig's close vents once more after a stop has completed and closed the log: that
    vent is kept with the commands but not logged (the log ends with the stop)."""
    keep = devices.commands.append

    def logged(command: list[Any]) -> None:
        keep(command)
        if log.closed:
            return
        psi = command[2] if command[0] == "set" else None
        log.event("pressure_command", t=command[1], command=command[0], psi=psi)

    devices.sink = logged


def dry_run_verdict(devices: ReplayDevices, sent: list[list[Any]], report: HarvestReport) -> int:
    """Compare what the dry run sent, and how each berry ended, with the recording;
    print the verdict and add it to ``report`` (``dry_run``). 0 when both match."""
    from softarm.harvest.rigs.replay.devices import compare_commands, recorded_commands
    from softarm.harvest.rigs.replay.dry_run import BERRY_STATES, berry_outcome

    found = compare_commands(sent, recorded_commands(devices.folder))
    ended = [berry_outcome(b) for b in report.berries]
    found["berries_as_recorded"] = ended == devices.folder.stream(BERRY_STATES)
    same = (
        found["first_mismatch"] is None
        and found["count"][0] == found["count"][1]
        and found["max_psi"] <= SAME_PSI
        and found["berries_as_recorded"]
    )
    report.extra["dry_run"] = {**found, "count": list(found["count"]), "same": same}
    n, m = found["count"]
    print(
        f"dry run: {n} pressure commands sent ({m} recorded), largest difference "
        f"{found['max_psi']:.3g} psi; every berry ended as recorded: "
        f"{'yes' if found['berries_as_recorded'] else 'no'} -> "
        + ("the same as the recording" if same else "NOT the same as the recording")
    )
    return 0 if same else 1
