"""Recording a simulated harvest for the dry run of the hardware path.

``softarm harvest --sim --world bush --record-frames DIR`` keeps, at the boundary
where the hardware rig meets its devices, everything the devices gave and took: each
camera frame with its time (:class:`~softarm.harvest.records.frame_files.FrameRecorder`), the
ripeness sensor's readings, and every pressure command sent. It writes ``DIR/hw.toml``,
the hardware configuration of the simulated rig (arm, channels, calibration, the
plant's declared lag, ``[perception]``) with its camera files. ``softarm harvest
--config DIR/hw.toml --frames DIR --dry-run`` then builds the hardware rig on
:class:`~softarm.harvest.rigs.replay.devices.ReplayDevices` and must send the same commands.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from softarm._core import SoftArm
from softarm.checks import FloatArray
from softarm.config import (
    ArmConfig,
    CalibrationConfig,
    CameraConfig,
    Config,
    GainsConfig,
    PlantModelConfig,
    SectionConfig,
    save_config,
)
from softarm.harvest.records.frame_files import FrameRecorder
from softarm.harvest.records.frame_index import BERRY_STATES, COMMANDS, RIPENESS
from softarm.harvest.records.report import BerryResult
from softarm.harvest.rigs.sim.bush_world import BushScene
from softarm.harvest_config import HarvestConfig
from softarm.identified_plant import IdentifiedPlant
from softarm.perception_config import PerceptionConfig, StereoSource
from softarm.vision.camera_model import CameraModel
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import StereoCamera
from softarm.vision.stereo_files import write_stereo

__all__ = [
    "BERRY_STATES",
    "COMMANDS",
    "CONFIG",
    "RIPENESS",
    "CommandTap",
    "RecordedSensor",
    "RigDescription",
    "berry_outcome",
    "write_rig_files",
]

#: The hardware configuration written beside the frames.
CONFIG = "hw.toml"


class CommandTap:
    """A pressure bank that passes every command on to ``outputs`` and hands it to
    ``sink`` first (``["set", t, psi]`` or ``["vent", t]``, ``t`` from ``now``)."""

    def __init__(
        self, outputs: Any, now: Callable[[], float], sink: Callable[[list[Any]], None]
    ) -> None:
        self.outputs, self.now, self.sink = outputs, now, sink

    @property
    def channels(self) -> int:
        return int(self.outputs.channels)

    @property
    def max_pressure(self) -> float:
        return float(self.outputs.max_pressure)

    def set_pressures(self, psi: FloatArray) -> None:
        self.sink(["set", self.now(), [float(p) for p in np.asarray(psi)]])
        self.outputs.set_pressures(psi)

    def vent(self) -> None:
        self.sink(["vent", self.now()])
        self.outputs.vent()

    def read_pressures(self) -> FloatArray:
        return np.asarray(self.outputs.read_pressures(), dtype=float)

    def close(self) -> None:
        self.outputs.close()


class RecordedSensor:
    """The ripeness ``sensor`` whose every reading is recorded."""

    def __init__(self, sensor: Any, recorder: FrameRecorder) -> None:
        self.sensor, self.recorder = sensor, recorder

    def read(self) -> float:
        value = float(self.sensor.read())
        self.recorder.record(RIPENESS, value)
        return value


@dataclass(frozen=True)
class RigDescription:
    """What a hardware configuration needs to know of a simulated rig: C1 as the
    ``scene`` registered it, the rest as the rig was built."""

    model: SoftArm
    harvest: HarvestConfig
    gains: dict[str, Any]
    plant: IdentifiedPlant
    scene: BushScene
    c2: CameraModel
    T_ee_c2: FloatArray
    T_ee_cube: FloatArray
    berry_tag: float
    T_base_tag: FloatArray
    #: The body carrying the tags C1 tracks, and their side (m): the replay must track
    #: the body the recording saw.
    marker_body: str
    marker_length: float
    #: Whether the rig surveyed the canes with C2 (``[perception] survey``).
    survey: bool = True

    @property
    def stereo(self) -> StereoCamera:
        """C1 as the registration placed it."""
        return self.scene.c1()

    @property
    def T_C1_base(self) -> FloatArray | None:
        """The base in C1, as the registration found it."""
        return self.scene.T_C1_base

    def config(self) -> Config:
        """The hardware configuration: the rig's arm, the default channels (the
        simulated bank's limits), C1 the stereo pair's left eye where the base tag
        registration put it, C2 in the palm, the plant's lag and play."""
        sections = tuple(
            SectionConfig(s.radius, s.rest_length, s.lower, s.upper, s.offset, s.twist)
            for s in self.model.sections
        )
        calibration = CalibrationConfig(
            c1=CameraConfig(0, file="c1.yml"),
            c2=CameraConfig(1, file="c2.yml"),
            T_C1_base=None if self.T_C1_base is None else _matrix(self.T_C1_base),
            T_C2_EE=_matrix(invert(self.T_ee_c2)),
            T_EE_cube=_matrix(self.T_ee_cube),
            berry_tag=self.berry_tag,
            T_base_tag=_matrix(self.T_base_tag),
            marker_body=self.marker_body,
            marker_length=self.marker_length,
        )
        return Config(
            ArmConfig(sections),
            GainsConfig(dict(self.gains)),
            calibration,
            plant_model=_plant_model(self.plant),
            harvest=self.harvest,
            perception=PerceptionConfig(
                StereoSource.PAIR, "stereo.yml", left=0, right=2, survey=self.survey
            ),
        )


def berry_outcome(result: BerryResult) -> list[Any]:
    """How a berry ended, as the dry run compares it: its final state, its fault,
    whether it was harvested, whether it was found unripe and released."""
    fault = None if result.fault is None else result.fault.value
    return [result.final_state.value, fault, result.harvested, result.skipped_unripe]


def write_rig_files(folder: str | Path, rig: RigDescription) -> Path:
    """``hw.toml``, ``stereo.yml``, ``c1.yml`` and ``c2.yml`` of ``rig`` in ``folder``;
    the path of ``hw.toml``."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    s = rig.stereo
    write_stereo(s, folder / "stereo.yml")
    s.left.save(folder / "c1.yml")
    rig.c2.save(folder / "c2.yml")
    save_config(rig.config(), folder / CONFIG)
    return folder / CONFIG


def _matrix(T: FloatArray) -> tuple[tuple[float, ...], ...]:
    return tuple(tuple(float(x) for x in row) for row in np.asarray(T))


def _plant_model(plant: IdentifiedPlant) -> PlantModelConfig:
    return PlantModelConfig(
        tau_s=tuple(plant.tau_s),
        metres_per_psi=tuple(plant.metres_per_psi),
        hysteresis_psi=tuple(plant.hysteresis_psi),
        dead_time_s=tuple(plant.dead_time_s),
        control_period_s=plant.control_period_s,
    )
