"""Bring up the harvesting arm's hardware step by step, and say what it would do when a
device is not attached.

    python examples/hardware_bringup.py                 # try every device
    python examples/hardware_bringup.py --dry-run       # open nothing, print the plan
    python examples/hardware_bringup.py --config my_arm.toml --port /dev/ttyUSB0

Five steps: load the configuration, open the NI-DAQmx pressure outputs (behind the safety
layer) and vent them, open the Arduino link (ping, gripper position, ripeness reading),
open both cameras and grab a frame. Nothing is pressurised: bring-up only vents.

Exit status: 0 when every device is either working or absent (the reason is printed),
1 when a device is present but fails, 2 when the configuration is invalid.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import replace

from softarm.commands._args import Parser, config_file
from softarm.config import Config, default_config, load_config
from softarm.errors import ConfigError, HardwareError, HardwareUnavailableError
from softarm.hardware.arduino import ArduinoLink
from softarm.hardware.arduino_devices import ArduinoGripper, ArduinoRipenessSensor
from softarm.hardware.camera import OpenCVCamera
from softarm.hardware.daq import NidaqPressureBank
from softarm.hardware.pressure_map import VoltageMap
from softarm.hardware.safety import SafePressureBank

OK, ABSENT, FAILED, PLANNED = "ok", "absent", "FAILED", "planned"


def pressure_step(config: Config) -> str:
    ch = config.channels
    vmap = VoltageMap(ch.full_scale_psi, *ch.voltage_range)
    bank = NidaqPressureBank(ch.names, vmap)
    with SafePressureBank(
        bank, ch.p_max, ch.max_rate_psi_per_s, ch.watchdog_timeout_s, watchdog_thread=False
    ) as safe:
        safe.vent("bring-up")
        return f"{safe.channels} channels open and vented"


def serial_step(config: Config) -> str:
    s = config.serial
    with ArduinoLink(
        s.port, s.baud, s.timeout_s, s.retries, startup_delay_s=s.startup_delay_s
    ) as link:
        firmware = link.ping()
        grip = ArduinoGripper(link).position
        ripeness = ArduinoRipenessSensor(link).read()
        return f"firmware {firmware!r}, gripper closure {grip:.2f}, ripeness {ripeness:.2f}"


def camera_step(source: int | str) -> str:
    cam = OpenCVCamera(source)
    try:
        frame = cam.read()
        return "opened, frame dropped" if frame is None else f"frame {frame.shape}"
    finally:
        cam.close()


def main(argv: list[str] | None = None) -> int:
    """Run the bring-up; returns the exit status."""
    parser = Parser(prog="hardware_bringup.py", description=__doc__.splitlines()[0])
    parser.add_argument(
        "--config", type=config_file, help="TOML config (default: shipped blackberry)"
    )
    parser.add_argument("--port", help="override serial.port")
    parser.add_argument("--dry-run", action="store_true", help="open nothing, print the plan")
    args = parser.parse_args(argv)

    print("[1/5] configuration")
    try:
        config = load_config(args.config) if args.config else default_config()
    except ConfigError as exc:
        print(f"      invalid configuration: {exc}")
        return 2
    if args.port:
        config = replace(config, serial=replace(config.serial, port=args.port))
    ch, cal = config.channels, config.calibration
    print(f"      {len(config.arm.sections)} sections, channels {', '.join(ch.names)}")

    steps: list[tuple[str, str, Callable[[], str]]] = [
        (
            "pressure outputs",
            f"open NI-DAQmx {ch.names[0]}..{ch.names[-1]} at "
            f"{ch.voltage_range[0]}-{ch.voltage_range[1]} V "
            f"({ch.full_scale_psi:.2f} psi full scale), vent all, p_max {ch.p_max} psi",
            lambda: pressure_step(config),
        ),
        (
            "arduino",
            f"open {config.serial.port} at {config.serial.baud} baud, PING, read "
            "gripper position and NIR ripeness",
            lambda: serial_step(config),
        ),
        (
            "camera C1",
            f"open OpenCV source {cal.c1.source!r}, grab one frame",
            lambda: camera_step(cal.c1.source),
        ),
        (
            "camera C2",
            f"open OpenCV source {cal.c2.source!r}, grab one frame",
            lambda: camera_step(cal.c2.source),
        ),
    ]
    results: list[tuple[str, str]] = [("configuration", OK)]
    for i, (name, plan, run) in enumerate(steps, start=2):
        print(f"[{i}/5] {name}")
        if args.dry_run:
            print(f"      would {plan}")
            results.append((name, PLANNED))
            continue
        try:
            print(f"      {run()}")
            results.append((name, OK))
        except HardwareUnavailableError as exc:
            print(f"      not attached: {exc}\n      would have: {plan}")
            results.append((name, ABSENT))
        except HardwareError as exc:
            print(f"      present but failing: {exc}")
            results.append((name, FAILED))

    print("\nsummary:")
    for name, status in results:
        print(f"  {name:<18} {status}")
    return 1 if any(status == FAILED for _, status in results) else 0


if __name__ == "__main__":
    sys.exit(main())
