"""From a :class:`~softarm.identification.record.Recording` to the identified plant:
lag and dead time per channel from the pressure readings (:mod:`.lag`), gains and
hysteresis from the tracked poses with the geometry fitted alongside
(:mod:`.kinematic`)."""

from __future__ import annotations

import dataclasses
import logging
import math
from typing import Any

import numpy as np

from softarm._core import SoftArm
from softarm.errors import HardwareError
from softarm.identification.kinematic import fit_kinematics
from softarm.identification.lag import fit_lag, simulate_lag
from softarm.identification.quality import poor_estimates
from softarm.identification.record import Recording
from softarm.identified_plant import IdentifiedPlant

__all__ = ["estimate"]

_log = logging.getLogger(__name__)

#: Fewer fitted holds than this cannot separate 30 parameters from tracker noise.
MIN_HOLDS = 20


def estimate(
    rec: Recording, nominal: SoftArm, metadata: dict[str, Any] | None = None
) -> IdentifiedPlant:
    """Identify the plant from ``rec``.

    Raises:
        HardwareError: the pressure readings are only echoes of the commands (no pressure
            monitor: the lag cannot be seen), or the tracker lost the arm on too many holds.
    """
    n = rec.sent.shape[1]
    if np.allclose(rec.pressure, rec.sent, atol=1e-9):
        # Without a monitor NidaqPressureBank echoes the commands: the lag is invisible
        # in the readings. (Fitting it from the poses' transients alone was tried and is
        # not reliable: the tracker's filter and the play hide the regulator's response.)
        raise HardwareError(
            "the pressure readings equal the commands: connect the regulators' pressure "
            "monitor (the Arduino pressure board) so that the lag can be measured"
        )
    lags = [
        fit_lag(rec.sent[:, i], rec.pressure[:, i], rec.period,
                float(rec.pressure_before[i]), float(rec.sent_before[i]))
        for i in range(n)
    ]  # fmt: skip
    seen = [h for h in rec.holds if h.fit and np.isfinite(rec.pose[h.end - 1]).all()]
    if len(seen) < MIN_HOLDS:
        raise HardwareError(
            f"the tracker saw the arm at the end of only {len(seen)} holds "
            f"(at least {MIN_HOLDS} are needed): check the cameras and the marker cube"
        )
    # The kinematic fit is driven by the fitted lag model's pressures, not the readings:
    # the same at the end of a hold, but free of the monitor's noise (noise in the
    # regressor would bias the gains towards zero).
    modelled = np.column_stack(
        [
            simulate_lag(rec.sent[:, i], rec.period, f.tau_s, f.dead_time_s,
                         float(rec.pressure_before[i]), float(rec.sent_before[i]))
            for i, f in enumerate(lags)
        ]
    )  # fmt: skip
    kin = fit_kinematics(dataclasses.replace(rec, pressure=modelled), nominal)
    meta: dict[str, Any] = {
        "arm_time_s": round(rec.duration, 3),
        "holds": len(rec.holds),
        "fitted_samples": kin.samples,
        "max_sent_psi": round(rec.max_sent_psi, 3),
        "commands_modified_by_safety": rec.clamped_or_limited,
        "pressure_rms_psi": [round(f.rms_psi, 6) for f in lags],
        "pose_rms_mm": round(kin.rms_position_m * 1e3, 4),
        "pose_rms_deg": round(math.degrees(kin.rms_angle_rad), 4),
        "metres_per_psi_std": kin.metres_per_psi_std.tolist(),
        "hysteresis_psi_std": kin.hysteresis_psi_std.tolist(),
        "fitted_sections": [
            {"radius": s.radius, "rest_length": s.rest_length, "offset": s.offset,
             "twist": s.twist}
            for s in kin.arm.sections
        ],
    }  # fmt: skip
    meta["poor_estimates"] = poor_estimates(
        kin.metres_per_psi, kin.metres_per_psi_std, kin.hysteresis_psi_std
    )
    if meta["poor_estimates"]:
        _log.warning("estimates beyond their tolerance: %s", "; ".join(meta["poor_estimates"]))
    meta.update(metadata or {})
    return IdentifiedPlant(
        tau_s=tuple(f.tau_s for f in lags),
        metres_per_psi=tuple(float(v) for v in kin.metres_per_psi),
        hysteresis_psi=tuple(float(v) for v in kin.hysteresis_psi),
        dead_time_s=tuple(f.dead_time_s for f in lags),
        control_period_s=rec.period,
        metadata=meta,
    )
