"""Runs the excitation on a rig and records what the hardware reports.

One sample per control period: the command asked for, what the safety layer sent, the
pressure readings and the tracked pose, all taken after the period has passed (sample
``k`` is the state after ``sent[k]`` was held for one period). The run stops before
the time budget would be exceeded, ramps every channel down under the rate limit and
vents; it vents on any error too.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softarm.checks import FloatArray as F64
from softarm.identification.protocol import Segment
from softarm.identification.rig import IdentificationRig

__all__ = ["HoldWindow", "Recording", "run_experiment"]


#: ``progress(arm_time_s, budget_s, what)`` after every segment.
Progress = Callable[[float, float, str], None]


@dataclass(frozen=True)
class HoldWindow:
    """The samples ``[start, end)`` of one hold, and what it was."""

    start: int
    end: int
    phase: str
    channel: int
    fit: bool


@dataclass
class Recording:
    """Everything measured, sample ``k`` at time ``t[k]``.

    ``pose[k]`` is NaN where the tracker lost the arm. ``pressure_before`` and
    ``sent_before`` are the state before the first sample (vented).
    """

    period: float
    pose_cutoff: float | None
    metres_per_psi: float
    t: F64
    command: F64
    sent: F64
    pressure: F64
    pose: F64
    pressure_before: F64
    sent_before: F64
    holds: list[HoldWindow] = field(default_factory=list)
    clamped_or_limited: int = 0
    max_sent_psi: float = 0.0

    @property
    def duration(self) -> float:
        """Arm time the experiment took (s)."""
        return float(self.t[-1]) if len(self.t) else 0.0


class _Recorder:
    """The samples of a run so far: one per control period, taken after the period."""

    def __init__(self, rig: IdentificationRig) -> None:
        self.rig = rig
        self.rows: dict[str, list[F64]] = {k: [] for k in ("command", "sent", "pressure", "pose")}
        self.times: list[float] = []
        self.modified = 0
        self.t0 = rig.now()

    def elapsed(self) -> float:
        """Arm time since the run started (s)."""
        return self.rig.now() - self.t0

    def step(self, cmd: F64) -> None:
        """Sends ``cmd`` through the safety layer, holds it one period and samples."""
        rig = self.rig
        result = rig.bank.set_pressures(cmd)
        self.modified += int(result.modified)
        rig.advance()
        pose = rig.pose()
        self.times.append(rig.now() - self.t0)
        self.rows["command"].append(np.asarray(cmd, dtype=np.float64).copy())
        self.rows["sent"].append(result.sent)
        self.rows["pressure"].append(np.asarray(rig.bank.read_pressures(), dtype=np.float64))
        self.rows["pose"].append(np.full((4, 4), np.nan) if pose is None else pose)

    def ramp(self, start: F64, seg: Segment) -> None:
        """From ``start`` to the segment's target in straight steps over its duration."""
        steps = max(1, math.ceil(seg.duration / self.rig.period))
        for j in range(1, steps + 1):
            self.step(start + (seg.target - start) * (j / steps))

    def hold(self, seg: Segment, settle_psi: float) -> HoldWindow:
        """Holds the segment's target for its duration, or from its minimum duration on
        as soon as every pressure reading is within ``settle_psi`` of what was sent (the
        regulators have arrived: waiting longer teaches nothing)."""
        start = len(self.times)
        k = 0
        while True:
            self.step(seg.target)
            k += 1
            held = k * self.rig.period
            settled = np.max(np.abs(self.rows["pressure"][-1] - self.rows["sent"][-1]))
            if held >= seg.duration - 1e-9 or (
                held >= seg.min_duration - 1e-9 and settled <= settle_psi
            ):
                break
        return HoldWindow(start, len(self.times), seg.phase, seg.channel, seg.fit)

    def ramp_down(self, budget_s: float) -> None:
        """Every channel down under the safety layer's rate limit (no whip), within the
        budget."""
        n = self.rig.bank.channels
        while np.max(self.rig.bank.last_sent) > 0.0 and self.elapsed() < budget_s:
            self.step(np.zeros(n))

    def recording(self, before: tuple[Any, Any], holds: list[HoldWindow]) -> Recording:
        """The samples as arrays, with the state ``before`` the first (pressures, sent)."""
        rig, n = self.rig, self.rig.bank.channels
        sent = np.array(self.rows["sent"]).reshape(-1, n)
        return Recording(
            period=rig.period,
            pose_cutoff=rig.pose_cutoff,
            metres_per_psi=rig.metres_per_psi,
            t=np.array(self.times),
            command=np.array(self.rows["command"]).reshape(-1, n),
            sent=sent,
            pressure=np.array(self.rows["pressure"]).reshape(-1, n),
            pose=np.array(self.rows["pose"]).reshape(-1, 4, 4),
            pressure_before=np.asarray(before[0], dtype=np.float64),
            sent_before=np.asarray(before[1], dtype=np.float64),
            holds=holds,
            clamped_or_limited=self.modified,
            max_sent_psi=float(sent.max()) if sent.size else 0.0,
        )


def _describe(seg: Segment) -> str:
    """What a segment does, for the progress report."""
    return seg.phase + (f" channel {seg.channel}" if seg.channel >= 0 else "")


def run_experiment(
    rig: IdentificationRig,
    segments: Iterable[Segment],
    budget_s: float,
    settle_psi: float = 0.3,
    progress: Progress | None = None,
) -> Recording:
    """Drive ``rig`` through ``segments`` within ``budget_s`` seconds of arm time.

    A segment starts only if it and the stop after it fit in what is left of the budget.

    Raises:
        SafetyError: the safety layer stopped the arm (its vent log says why).
        HardwareError: a device failed; the arm is vented first.
    """
    before = (rig.bank.read_pressures(), rig.bank.last_sent)
    rec = _Recorder(rig)
    holds: list[HoldWindow] = []
    # What stopping takes: the slowest channel ramped to 0 at the rate limit, plus margin.
    stop_time = rig.bank.max_pressure / rig.bank.max_rate + 2 * rig.period
    previous = np.zeros(rig.bank.channels)
    try:
        for seg in segments:
            need = seg.duration + stop_time
            if rec.elapsed() + need > budget_s:
                break
            if seg.kind == "ramp":
                rec.ramp(previous, seg)
            else:
                holds.append(rec.hold(seg, settle_psi))
            previous = np.asarray(seg.target, dtype=np.float64)
            if progress is not None:
                progress(rec.elapsed(), budget_s, _describe(seg))
        rec.ramp_down(budget_s)
    except BaseException:  # device errors, a refused command, SIGINT/SIGTERM alike
        rig.bank.vent("identification aborted")
        raise
    rig.bank.vent("identification done")
    return rec.recording(before, holds)
