"""The dry run's devices: the hardware rig's boundary (:class:`~softarm.harvest.
hw_devices.Devices`) fed from a recording (:mod:`softarm.harvest.rigs.replay.dry_run`).

The cameras read the recorded frames, each at the time it was recorded; the Arduino
answers the gripper's commands and gives the recorded ripeness readings; the pressure
outputs keep every command instead of driving a regulator; the clock steps by the
control periods the loop sleeps. Everything between these and the devices is the
hardware path itself.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from contextlib import ExitStack
from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.config import Config
from softarm.errors import HardwareError
from softarm.harvest.records.frame_files import FrameFolder
from softarm.harvest.records.frame_index import COMMANDS, RIPENESS, SEED
from softarm.harvest.rigs.replay.dry_run import CommandTap
from softarm.harvest.rigs.sim.devices import SimClock
from softarm.perception.c1 import Pair
from softarm.perception_config import PerceptionConfig
from softarm.vision.two_cameras import Frame

__all__ = [
    "DryOutputs",
    "RecordingExhaustedError",
    "ReplayDevices",
    "ReplayLink",
    "compare_commands",
]


class RecordingExhaustedError(HardwareError):
    """The replayed device has no recorded reply left for what the dry run asks: it went
    further than the recorded run (another ripeness reading, a command never sent). A
    device error, so the machine ends the berry in FAULT with this message as its
    stated reason, vented, and stops the run (nothing further can be replayed)."""


class DryOutputs:
    """Pressure outputs that drive nothing: they keep the last command (the vent is
    all zeros)."""

    def __init__(self, channels: int, max_pressure: float) -> None:
        self._n, self._max = channels, max_pressure
        self._last = np.zeros(channels)

    @property
    def channels(self) -> int:
        return self._n

    @property
    def max_pressure(self) -> float:
        return self._max

    def set_pressures(self, psi: FloatArray) -> None:
        self._last = np.array(psi, dtype=float)

    def vent(self) -> None:
        self._last = np.zeros(self._n)

    def read_pressures(self) -> FloatArray:
        return self._last.copy()

    def close(self) -> None:
        self.vent()


class ReplayLink:
    """The Arduino as the recording saw it: ``GRIP`` moves the servo (kept),
    ``GPOS`` reads it back, ``NIR`` gives the next recorded ripeness reading."""

    def __init__(self, ripeness: list[float], where: str) -> None:
        self._ripeness = iter(ripeness)
        self._where = where
        self._angle = "0.0"

    def request(self, command: str, *args: object) -> list[str]:
        if command == "GRIP":
            self._angle = str(args[0])
            return []
        if command == "GPOS":
            return [self._angle]
        if command == "NIR":
            value = next(self._ripeness, None)
            if value is None:
                raise RecordingExhaustedError(
                    f"{self._where}: no ripeness reading left to replay (the dry run read "
                    "more than the recorded run did)"
                )
            return [repr(float(value))]
        raise RecordingExhaustedError(f"{self._where}: the recording has no reply to {command!r}")

    def close(self) -> None:
        pass


class ReplayDevices:
    """The devices of a recording in ``folder``; :attr:`commands` collects what the
    rig sends, in the recording's form (``["set", t, psi]``, ``["vent", t]``)."""

    def __init__(self, folder: FrameFolder) -> None:
        self.folder = folder
        self.commands: list[list[Any]] = []
        #: Where each command goes (the dry run also logs it).
        self.sink: Callable[[list[Any]], None] = self.commands.append
        self._clock = SimClock()

    def recorded_seed(self) -> int:
        """The seed the recorded run's planner used."""
        return int(self.folder.stream(SEED)[0])

    def clock(self) -> SimClock:
        return self._clock

    def pressure_outputs(self, config: Config, stack: ExitStack) -> CommandTap:
        ch = config.channels
        outputs = DryOutputs(len(ch.names), ch.full_scale_psi)
        return CommandTap(outputs, self._clock.now, lambda command: self.sink(command))

    def arduino(self, config: Config, stack: ExitStack) -> ReplayLink:
        return ReplayLink(self.folder.stream(RIPENESS), str(self.folder.folder))

    def stereo(self, perception: PerceptionConfig, stack: ExitStack) -> Callable[[], Pair]:
        return self.folder.pair(self._clock.now)

    def c1_frames(self, config: Config, stack: ExitStack, stereo_left: Frame | None) -> Frame:
        return self.folder.frame("c1")

    def c2_frames(self, config: Config, stack: ExitStack) -> Frame:
        return self.folder.frame("c2")


def compare_commands(sent: list[list[Any]], recorded: list[list[Any]]) -> dict[str, Any]:
    """How the commands ``sent`` compare with the ``recorded`` ones: ``count`` (both),
    ``max_psi`` (the largest difference of a pressure, over the shared commands),
    ``max_t`` (of a time) and ``first_mismatch`` (the index of the first command of
    another kind or length, None when every shared one matches)."""
    max_psi = max_t = 0.0
    first: int | None = None
    for i, (a, b) in enumerate(zip(sent, recorded, strict=False)):
        if a[0] != b[0] or len(a) != len(b) or (a[0] == "set" and len(a[2]) != len(b[2])):
            first = i
            break
        max_t = _worst(max_t, [a[1] - b[1]])
        if a[0] == "set":
            max_psi = _worst(max_psi, np.subtract(a[2], b[2]))
    return {
        "count": (len(sent), len(recorded)),
        "max_psi": max_psi,
        "max_t": max_t,
        "first_mismatch": first,
    }


def _worst(worst: float, differences: Any) -> float:
    """The larger of ``worst`` and the largest magnitude of ``differences``; infinite
    when one is not finite (``max(0.0, nan)`` would keep 0.0 and call NaN the same)."""
    d = np.abs(np.asarray(differences, dtype=float))
    return max(worst, float(np.max(d))) if np.all(np.isfinite(d)) else math.inf


def recorded_commands(folder: FrameFolder) -> list[list[Any]]:
    """The commands the recorded rig sent."""
    return list(folder.stream(COMMANDS))
