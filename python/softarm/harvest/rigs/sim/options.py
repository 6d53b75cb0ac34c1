"""The simulated rig's options (:class:`SimRigOptions`), its cameras' default placement
(:func:`default_cameras`) and the plant as its description declares it
(:func:`declared_plant`)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from softarm.calibration.result import Calibration
from softarm.harvest.control.stack import LagControl
from softarm.harvest_config import HarvestConfig
from softarm.identified_plant import IdentifiedPlant
from softarm.sim.arm import PlantConfig
from softarm.sim.rig_cameras import SimCameras, look_at
from softarm.sim.world import WorldName
from softarm.units import METRES_PER_PSI
from softarm.vision.marker_body import SIMULATED_BODY

__all__ = ["SimRigOptions", "declared_plant", "default_cameras"]


@dataclass
class SimRigOptions:
    """Knobs of the simulated rig.

    ``scale`` shrinks both images (and focal lengths) for speed; ``hidden`` occludes the
    selected berry from both cameras at the times it returns True (a leaf);
    ``avoid_canes`` passes the canes to the resolver as obstacles (planning paper eq. 9,
    below position and orientation); ``joint_limit_gain`` overrides the closed-loop
    resolver's γ of eq. (20).
    """

    n_berries: int = 5
    seed: int = 0
    scale: float = 1.0
    noise_std: float = 2.0
    unripe_fraction: float = 0.0
    config: HarvestConfig = field(default_factory=HarvestConfig)
    log_path: str | Path | None = None
    hidden: Callable[[float], bool] | None = None
    avoid_canes: bool = True
    joint_limit_gain: float | None = None
    #: The simulated plant's parameters (``--plant FILE``, :mod:`softarm.sim.plant_file`).
    plant: PlantConfig = field(default_factory=PlantConfig)
    #: The plant `softarm identify` measured (``--identified id.json``), for lag-aware control.
    identified: IdentifiedPlant | None = None
    #: A fitted model (``softarm calibrate``, ``--model model.toml``): the controller's arm
    #: and the actuators' gains; None: the nominal blackberry arm.
    calibration: Calibration | None = None
    #: How the loop handles the plant's lag (docs/control.md, section 6): "predictor" (a
    #: lag model of every command sent, regulators then pose filter, whose motion still
    #: in flight each step takes out of the measured error; the mode's gain) or "bound"
    #: (no model: the gain bounded by the whole lag, `Gains.for_lag`).
    lag_control: LagControl = LagControl.PREDICTOR
    #: "tags": every berry wears an ArUco tag and the canes are mapped (fast, for
    #: controller sweeps); "bush": the rendered bush, berries and canes found by
    #: perception (softarm.perception), the markerless harvest; "row": the same in
    #: the daylight row around the bush (softarm.sim.render.row).
    world: WorldName = WorldName.TAGS
    #: ``world = "row"``: the daylight family (softarm.sim.render.row_look.LOOKS; None:
    #: "random", one of them drawn from the seed).
    look: str | None = None
    #: In the rendered bush, C2 surveys the canes C1 fitted before the first berry
    #: (:mod:`softarm.harvest.runs.cane_survey`; ``--no-survey`` turns it off), as the
    #: hardware does unless ``[perception] survey = false``.
    survey: bool = True
    #: The rendered worlds' berry detector (softarm.perception.detector.choice.DETECTORS),
    #: as ``[perception] detector`` sets the hardware's.
    detector: str = "colour"
    #: The rendered worlds' cane pixels (softarm.perception.cane_source.CANE_SOURCES),
    #: as ``[perception] canes`` sets the hardware's.
    cane_source: str = "colour"
    #: Resolver gain keywords (``--gains``) over every controller resolver's own.
    gains: Mapping[str, Any] = field(default_factory=dict)
    #: A folder to record the rendered bush's frames, the ripeness readings and the
    #: pressure commands in, with the rig's hw.toml: the dry run's input
    #: (:mod:`softarm.harvest.rigs.replay.dry_run`).
    record_frames: str | Path | None = None
    #: The gripper's marker body C1 tracks (softarm.vision.marker_body.MARKER_BODIES;
    #: ``--marker-body``), drawn in every world; hw.toml's ``[calibration] marker_body``.
    marker_body: str = SIMULATED_BODY

    def __post_init__(self) -> None:
        self.world = WorldName.parse(self.world)  # a name given as a string, checked


def default_cameras(scale: float = 1.0, noise_std: float = 2.0) -> SimCameras:
    """C1 about 1 m from the workspace, looking across it from +X/-Y so that it sees the
    cube's side faces, the base tag and the berry tags (section II-C); C2 at the centre
    of the gripper (3 cm behind its frame) looking along its axis; the cube 5 cm behind
    the gripper frame."""
    centre = np.array([0.0, 0.25, 0.3])
    eye = np.array([0.7, -0.45, 0.55])
    tag = np.eye(4)
    tag_pos = np.array([0.15, -0.05, 0.2])  # on a bracket of the chassis
    # The base tag faces the camera, its y axis up.
    tag[:3, :3] = look_at(tag_pos, eye)[:3, :3] @ np.diag([-1.0, -1.0, 1.0])
    tag[:3, 3] = tag_pos
    cube = np.eye(4)
    cube[2, 3] = -0.05
    c2 = np.eye(4)
    c2[2, 3] = -0.03  # in the palm, 6 cm behind the grasp point: the whole tag stays in view
    return SimCameras(
        T_base_c1=look_at(eye, centre),
        T_ee_c2=c2,
        T_ee_cube=cube,
        T_base_tag=tag,
        noise_std=noise_std,
        scale=scale,
    )


def declared_plant(plant: PlantConfig, n: int, period: float) -> IdentifiedPlant:
    """The simulated plant as its description declares it, in the form `softarm
    identify` measures: every regulator's time constant, no dead time, the nominal
    elongation per psi and the declared play band."""
    return IdentifiedPlant(
        tau_s=(plant.pressure_tau,) * n,
        metres_per_psi=(METRES_PER_PSI,) * n,
        hysteresis_psi=(plant.hysteresis_psi,) * n,
        dead_time_s=(0.0,) * n,
        control_period_s=period,
    )
