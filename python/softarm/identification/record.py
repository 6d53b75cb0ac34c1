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


def run_experiment(
    rig: IdentificationRig,
    segments: Iterable[Segment],
    budget_s: float,
    settle_psi: float = 0.3,
    progress: Progress | None = None,
) -> Recording:
    """Drive ``rig`` through ``segments`` within ``budget_s`` seconds of arm time.

    Raises:
        SafetyError: the safety layer stopped the arm (its vent log says why).
        HardwareError: a device failed; the arm is vented first.
    """
    dt = rig.period
    n = rig.bank.channels
    rows: dict[str, list[F64]] = {k: [] for k in ("command", "sent", "pressure", "pose")}
    times: list[float] = []
    holds: list[HoldWindow] = []
    rec_before = (rig.bank.read_pressures(), rig.bank.last_sent)
    modified = 0
    t0 = rig.now()
    # What stopping takes: the slowest channel ramped to 0 at the rate limit, plus margin.
    p_max = rig.bank.max_pressure

    def stop_time() -> float:
        return p_max / 100.0 + 2 * dt

    def step(cmd: F64) -> None:
        nonlocal modified
        result = rig.bank.set_pressures(cmd)
        modified += int(result.modified)
        rig.advance()
        pose = rig.pose()
        times.append(rig.now() - t0)
        rows["command"].append(np.asarray(cmd, dtype=np.float64).copy())
        rows["sent"].append(result.sent)
        rows["pressure"].append(np.asarray(rig.bank.read_pressures(), dtype=np.float64))
        rows["pose"].append(np.full((4, 4), np.nan) if pose is None else pose)

    previous = np.zeros(n)
    try:
        for seg in segments:
            elapsed = rig.now() - t0
            need = seg.duration + stop_time()
            if elapsed + need > budget_s:
                break
            if seg.kind == "ramp":
                steps = max(1, math.ceil(seg.duration / dt))
                for j in range(1, steps + 1):
                    step(previous + (seg.target - previous) * (j / steps))
            else:
                start = len(times)
                k = 0
                while True:
                    step(seg.target)
                    k += 1
                    held = k * dt
                    settled = np.max(np.abs(rows["pressure"][-1] - rows["sent"][-1]))
                    if held >= seg.duration - 1e-9 or (
                        held >= seg.min_duration - 1e-9 and settled <= settle_psi
                    ):
                        break
                holds.append(HoldWindow(start, len(times), seg.phase, seg.channel, seg.fit))
            previous = np.asarray(seg.target, dtype=np.float64)
            if progress is not None:
                what = seg.phase + (f" channel {seg.channel}" if seg.channel >= 0 else "")
                progress(rig.now() - t0, budget_s, what)
        # Down under the rate limit (no whip), then vent.
        while np.max(rig.bank.last_sent) > 0.0 and rig.now() - t0 < budget_s:
            step(np.zeros(n))
    except BaseException:  # device errors, a refused command, SIGINT/SIGTERM alike
        rig.bank.vent("identification aborted")
        raise
    rig.bank.vent("identification done")
    sent = np.array(rows["sent"]).reshape(-1, n)
    return Recording(
        period=dt,
        pose_cutoff=rig.pose_cutoff,
        metres_per_psi=rig.metres_per_psi,
        t=np.array(times),
        command=np.array(rows["command"]).reshape(-1, n),
        sent=sent,
        pressure=np.array(rows["pressure"]).reshape(-1, n),
        pose=np.array(rows["pose"]).reshape(-1, 4, 4),
        pressure_before=np.asarray(rec_before[0], dtype=np.float64),
        sent_before=np.asarray(rec_before[1], dtype=np.float64),
        holds=holds,
        clamped_or_limited=modified,
        max_sent_psi=float(sent.max()) if sent.size else 0.0,
    )
