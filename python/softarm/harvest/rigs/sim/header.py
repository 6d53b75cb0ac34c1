"""The header's settings of a simulated rig: seed, world, plant, arm, frames and cameras
(the record itself: :func:`softarm.harvest.records.header.header_record`)."""

from __future__ import annotations

import dataclasses
from typing import Any

from softarm.harvest.records.header import (
    arm_settings,
    camera,
    frame,
    pressure_settings,
    world_settings,
)
from softarm.harvest.rigs.sim.options import SimRigOptions, default_cameras
from softarm.harvest.rigs.sim.rig import SimRig

__all__ = ["sim_settings"]


def sim_settings(rig: SimRig, options: SimRigOptions) -> dict[str, Any]:
    """The settings of a simulated rig built from ``options`` (``SimRigOptions``)."""
    cams = default_cameras(options.scale, options.noise_std)
    plant = dataclasses.asdict(options.plant)
    return {
        "seed": options.seed,
        "berries": options.n_berries,
        # Every cane drawn (the row's own too, which the arm can touch): the truth the
        # contacts and the report's cane map are scored on.
        "world": world_settings(
            rig.bush,
            options.unripe_fraction,
            str(getattr(options, "world", "tags")),
            canes=rig.watch.clearance.canes,
        ),
        "plant": plant,
        "arm": arm_settings(rig.model),
        "grasp_offset_m": options.config.grasp_offset,
        "marker_body": options.marker_body,
        "pressure_map": pressure_settings(
            None if options.calibration is None else options.calibration.pressure_map(),
            rig.model.n_actuators,
        ),
        "frames": {
            "camera_c1": frame("base", cams.T_base_c1),
            "camera_c2": frame("gripper", cams.T_ee_c2),
            "cube": frame("gripper", cams.T_ee_cube),
            "base_tag": frame("base", cams.T_base_tag),
        },
        "cameras": {"camera_c1": camera(cams.model(1)), "camera_c2": camera(_c2(rig, cams))},
    }


def _c2(rig: SimRig, cams: Any) -> Any:
    """C2's intrinsics as the rig renders it: the rendered bush's (half size), else the
    synthetic cameras'."""
    scene = getattr(rig, "scene", None)
    return cams.model(2) if scene is None else scene.world.c2
