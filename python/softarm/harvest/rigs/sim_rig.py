"""The full simulated harvest: bush → synthetic cameras → vision → fusion → resolver →
safety layer → simulated pneumatic arm, on a simulated clock.

:func:`build_sim_rig` wires it; :meth:`SimRig.run` harvests every berry of the bush and
returns the report with ground-truth errors and the arm's clearance to the canes.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

import softarm
from softarm.calibration.result import Calibration
from softarm.checks import FloatArray
from softarm.config import ChannelsConfig
from softarm.errors import ParameterError
from softarm.hardware import SafePressureBank, SimulatedPressureBank
from softarm.hardware.pressure_map import ElongationMap
from softarm.harvest.control.actuator import PressureMap
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.stack import ControlInputs, ControlStack, build_control_stack
from softarm.harvest.machine.harvest_machine import HarvestMachine
from softarm.harvest.machine.interfaces import Controller
from softarm.harvest.records.frame_files import FrameRecorder
from softarm.harvest.records.log import HarvestLog
from softarm.harvest.records.rate import rate_record
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.rigs.bush_world import BushGripper, BushScene, RenderedWorld
from softarm.harvest.rigs.dry_run import (
    BERRY_STATES,
    COMMANDS,
    CommandTap,
    RecordedSensor,
    RigDescription,
    berry_outcome,
    write_rig_files,
)
from softarm.harvest.rigs.sim_devices import ArmWatch, SimClock, SimGripper
from softarm.harvest.rigs.tag_world import TagWorld
from softarm.harvest.runs.cane_survey import CaneSurvey
from softarm.harvest_config import HarvestConfig
from softarm.identified_plant import IdentifiedPlant
from softarm.perception.bush_map import BushMap
from softarm.perception.bush_vision import BushVision
from softarm.perception.cane_source import use_cane_source
from softarm.perception.detector.choice import use_detector
from softarm.perception.self_filter import CANE_REACH, rig_parts
from softarm.sim.arm import PlantConfig, SimulatedArm
from softarm.sim.bush import Bush
from softarm.sim.plant import ArmPlant
from softarm.sim.render.row_look import RowLook
from softarm.sim.render.world import world_for
from softarm.sim.rig_cameras import BASE_TAG_ID, SimCameras, look_at, sim_vision
from softarm.sim.world import World, WorldName
from softarm.units import MAX_PSI, METRES_PER_PSI
from softarm.vision.marker_body import check_marker_body, marker_body
from softarm.vision.poses import invert
from softarm.vision.two_cameras import CameraVision, register_c1

__all__ = [
    "WORLDS",
    "HarvestWorld",
    "SimRig",
    "SimRigOptions",
    "build_sim_rig",
    "control_inputs",
    "default_cameras",
    "sim_bush",
]


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
    lag_control: str = "predictor"
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
    #: (:mod:`softarm.harvest.rigs.dry_run`).
    record_frames: str | Path | None = None
    #: The gripper's marker body C1 tracks (softarm.vision.marker_body.MARKER_BODIES;
    #: ``--marker-body``), drawn in every world; hw.toml's ``[calibration] marker_body``.
    marker_body: str = "cube"

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


class HarvestWorld(World, Protocol):
    """A :class:`~softarm.sim.world.World` the simulated rig harvests: its berry source
    run by the run policy (:class:`~softarm.harvest.rigs.tag_world.TagWorld`,
    :class:`~softarm.harvest.rigs.bush_world.RenderedWorld`)."""

    def harvest(
        self, machine: HarvestMachine, on_berry: Callable[[int, BerryResult], None] | None
    ) -> HarvestReport:
        """The world's berries through ``machine``; the run finished by the policy."""
        ...

    @property
    def vision(self) -> CameraVision:
        """The world's two cameras: the synthetic ones, or the rendered world's."""
        ...

    @property
    def gripper(self) -> SimGripper:
        """The simulated gripper, closing on the world's true berries."""
        ...

    def survey(
        self, machine: HarvestMachine, stack: ControlStack, parts: FloatArray
    ) -> CaneSurvey | None:
        """C2's survey of the canes the world's C1 fitted (the rig's own ``parts`` left
        out), or None where the canes are mapped or the survey is off."""
        ...


@dataclass
class SimRig:
    """Everything wired (see :func:`build_sim_rig`)."""

    bush: Bush
    model: softarm.SoftArm
    plant: ArmPlant
    clock: SimClock
    bank: SafePressureBank
    world: HarvestWorld
    watch: ArmWatch
    machine: HarvestMachine
    #: What ``record_frames`` records into, None without it.
    recorder: FrameRecorder | None = None
    #: C2's survey of the canes (the rendered worlds with ``survey``), flown first.
    survey: CaneSurvey | None = None

    @property
    def vision(self) -> CameraVision:
        """The world's cameras as the harvest sees them."""
        return self.world.vision

    @property
    def gripper(self) -> SimGripper:
        """The world's gripper (device, ripeness sensor, ground truth)."""
        return self.world.gripper

    @property
    def scene(self) -> BushScene | None:
        """The rendered world's scene and map (C1's picture), None in the tag world."""
        return getattr(self.world, "scene", None)

    def run(self, on_berry: Callable[[int, BerryResult], None] | None = None) -> HarvestReport:
        """Harvest the world's berries by the run policy both rigs follow
        (:mod:`softarm.harvest.runs.policy`), the survey first where there is one;
        ``on_berry(i, result)`` after each attempt. The report keeps each berry's last
        attempt."""
        try:
            if self.survey is not None:
                self.survey.run()
            return self._finish(self.world.harvest(self.machine, on_berry))
        except BaseException:
            if self.recorder is not None:  # an unfinished recording is not left behind
                self.recorder.discard()
            raise

    def close(self) -> None:
        """Free the world's renderer contexts (if any) now, rather than in finalizers at
        exit, where a stop signal would be lost, and drop a recording the run did not
        finish. Harmless twice."""
        if self.recorder is not None:
            self.recorder.discard()
        self.world.close()

    def _finish(self, report: HarvestReport) -> HarvestReport:
        report.extra.update(
            seed=self.bush.seed,
            min_branch_gap_m=self.watch.min_gap,
            branch_contact_steps=self.watch.contacts,
            sim_time_s=self.clock.now(),
            rate=rate_record(self.machine.log.records, report.harvested, self.clock.now()),
        )
        self.machine.log.close()
        if self.recorder is not None:
            for berry in report.berries:
                self.recorder.record(BERRY_STATES, berry_outcome(berry))
            self.recorder.save()
        return report


def build_sim_rig(
    options: SimRigOptions | None = None, controller: Controller | None = None
) -> SimRig:
    """A simulated rig for ``options`` (a fresh bush, plant and cameras from the seed);
    ``controller`` defaults to the control stack's (:func:`~softarm.harvest.control.stack.
    build_control_stack`, the same as the hardware's)."""
    o = options or SimRigOptions()
    recorder = _recorder(o)  # first: a folder it may not replace is refused before work
    try:
        return _build_sim_rig(o, controller, recorder)
    except BaseException:
        if recorder is not None:  # no unfinished recording is left behind
            recorder.discard()
        raise


def _build_sim_rig(
    o: SimRigOptions, controller: Controller | None, recorder: FrameRecorder | None
) -> SimRig:
    cfg = o.config
    nominal = softarm.SoftArm.blackberry()
    model = nominal if o.calibration is None else o.calibration.arm
    plant = _plant(o, nominal)
    cams = default_cameras(o.scale, o.noise_std)
    cams.marker_body = check_marker_body(o.marker_body)
    bush = _bush(o, plant, cams)
    canes = [b.curve() for b in bush.branches]  # the truth: contacts are scored on it
    watch = _watch(o, plant, canes)
    clock = SimClock([plant.advance, watch.sample])
    bank = _bank(plant, clock, recorder)
    parts = rig_parts(model, cfg, cams.T_ee_cube, cams.T_base_tag)
    world = WORLDS[o.world](WorldParts(o, bush, canes, plant, model, cams, parts, clock, recorder))
    stack = build_control_stack(
        cfg, control_inputs(o, model), list(world.known_canes()), bank, clock.now
    )
    gripper = world.gripper
    sensor = gripper if recorder is None else RecordedSensor(gripper, recorder)
    machine = HarvestMachine(
        clock, world.vision, controller or stack.controller, stack.actuator, gripper, sensor,
        n_actuators=model.n_actuators, config=cfg, log=HarvestLog(o.log_path),
        ground_truth=gripper, planner=stack.planner,
    )  # fmt: skip
    survey = world.survey(machine, stack, parts)
    return SimRig(bush, model, plant, clock, bank, world, watch, machine, recorder, survey)


def sim_bush(options: SimRigOptions) -> Bush:
    """The bush :func:`build_sim_rig` harvests for ``options``, without the rig: the same
    seed draws the same plant and bush (a replay's scene needs no cameras or renderer)."""
    plant = _plant(options, softarm.SoftArm.blackberry())
    return _bush(options, plant, default_cameras(options.scale, options.noise_std))


def control_inputs(o: SimRigOptions, model: softarm.SoftArm) -> ControlInputs:
    """The control stack's inputs of ``o``: the plant's lag and play measured by
    `softarm identify` when given, else declared by the plant description (its
    regulators' time constant, as a datasheet states it), as the hardware's
    ``[plant_model]`` gives them."""
    return ControlInputs.of_plant(
        model,
        _pressure_map(o),
        o.identified or declared_plant(o.plant, model.n_actuators, o.config.period),
        gains=dict(o.gains),
        lag_control=o.lag_control,
        joint_limit_gain=o.joint_limit_gain,
        avoid_canes=o.avoid_canes,
        seed=o.seed,
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


def _pressure_map(o: SimRigOptions) -> PressureMap:
    """Elongation to psi: the fitted model's (``--model``), else the channels' nominal
    map, as the hardware's ``[channels]`` give it."""
    if o.calibration is not None:
        return o.calibration.pressure_map()
    ch = ChannelsConfig()
    return ElongationMap(ch.p_max, ch.metres_per_psi)


def _bush(o: SimRigOptions, plant: ArmPlant, cams: SimCameras) -> Bush:
    """The bush of ``o``'s seed, in the true actuators' reach: 0-70 psi (or less if the
    regulators saturate lower) through each one's true elongation per psi."""
    if o.look is not None and o.world is not WorldName.ROW:
        raise ParameterError(f"look = {o.look!r}: for the rendered row (world = 'row')")
    true_upper = min(MAX_PSI, o.plant.max_psi) * plant.sim.metres_per_psi
    return Bush.generate(
        plant.arm, o.n_berries, o.seed, grasp_offset=o.config.grasp_offset,
        unripe_fraction=o.unripe_fraction, view_point=cams.T_base_c1[:3, 3],
        limits=(np.zeros_like(true_upper), true_upper), cone_deg=o.config.approach_cone_deg,
    )  # fmt: skip


def _recorder(o: SimRigOptions) -> FrameRecorder | None:
    """The recorder of ``--record-frames`` (the rendered bush only)."""
    if o.record_frames is None:
        return None
    if not o.world.rendered:
        raise ParameterError(
            "record_frames: records the rendered worlds (world = 'bush' or 'row') only"
        )
    recorder = FrameRecorder(o.record_frames)
    recorder.record("seed", o.seed)
    return recorder


def _bank(plant: ArmPlant, clock: SimClock, recorder: FrameRecorder | None) -> SafePressureBank:
    """The simulated regulators behind the safety layer with the channels' limits (the
    hardware's ``[channels]`` defaults); each command recorded for the dry run."""
    outputs: Any = SimulatedPressureBank(plant, plant.arm.n_actuators)
    if recorder is not None:
        outputs = CommandTap(outputs, clock.now, lambda c: recorder.record(COMMANDS, c))
    ch = ChannelsConfig()
    return SafePressureBank(
        outputs, ch.p_max, ch.max_rate_psi_per_s, ch.watchdog_timeout_s, clock.now,
        watchdog_thread=False, simulated=True,
    )  # fmt: skip


def _plant(o: SimRigOptions, nominal: softarm.SoftArm) -> ArmPlant:
    """The simulated plant of ``o``; softarm identify/calibrate --sim --seed S measure
    this same plant (seed S + 1000)."""
    if o.plant.model == "cosserat":  # optional extra: pyelastica
        from softarm.sim.cosserat import CosseratPlant

        return CosseratPlant(nominal, o.plant, seed=o.seed + 1000)
    if o.plant.model == "pcc":
        return ArmPlant(SimulatedArm(nominal, o.plant, seed=o.seed + 1000))
    raise ParameterError(f"plant.model = {o.plant.model!r}: must be 'pcc' or 'cosserat'")


def _watch(o: SimRigOptions, plant: ArmPlant, canes: list[softarm.PolynomialCurve]) -> ArmWatch:
    """The true arm's clearance to the true ``canes``, sampled every tick."""
    if o.plant.model == "cosserat":  # the rod's centre line, not arcs
        from softarm.sim.cosserat.clearance import RodClearance

        return ArmWatch(plant, RodClearance(plant, canes, o.config.grasp_offset))  # type: ignore[arg-type]
    return ArmWatch(plant, Clearance(plant.arm, canes, o.config.grasp_offset))


#: C2's image in the rendered bush is rendered at half size (320 x 240): the berry
#: fills much of it in the last centimetres, and the software rasteriser's cost goes
#: with the pixels.
C2_SCALE = 0.5


@dataclass(frozen=True)
class WorldParts:
    """What a world is built from: the options, the true bush and canes, the plant, the
    controller's model, the cameras, the rig's own parts (C1's self-filter), the clock
    and the recorder of ``record_frames``."""

    o: SimRigOptions
    bush: Bush
    true_canes: list[softarm.PolynomialCurve]
    plant: ArmPlant
    model: softarm.SoftArm
    cams: SimCameras
    parts: FloatArray
    clock: SimClock
    recorder: FrameRecorder | None


def _tag_world(w: WorldParts) -> TagWorld:
    """The tagged bush seen by the synthetic cameras, its true canes mapped."""
    cfg, on_bush = w.o.config, list(w.bush.berries)
    vision = sim_vision(
        w.cams, w.plant.pose, lambda: on_bush, cfg.grasp_offset, seed=w.o.seed, hidden=w.o.hidden
    )
    gripper = SimGripper(w.plant, vision, on_bush, cfg.grasp_offset, cfg.grasp_workspace)
    return TagWorld(w.bush, vision, gripper, w.true_canes)


def _rendered_world(w: WorldParts) -> RenderedWorld:
    """The rendered bush (in the row for ``world = "row"``) and its map, the markerless
    vision, the gripper that closes on the true berry a map entry stands for, and the
    canes the planner, the resolver and the clearance avoid: fitted from C1 without the
    rig's own parts. With a recorder every frame is recorded, and the rig's hardware
    configuration written beside."""
    o, cfg = w.o, w.o.config
    use_detector(o.detector)
    use_cane_source(o.cane_source)
    scene = _bush_scene(w.bush, w.plant, w.cams, w.clock, w.recorder, _look(o, w.bush))
    canes = scene.fit_canes(w.parts, CANE_REACH)
    vision = _bush_vision(scene, w.cams, cfg.grasp_offset, w.recorder)
    gripper = BushGripper(
        scene, w.plant, vision, list(w.bush.berries), cfg.grasp_offset, cfg.grasp_workspace
    )
    if w.recorder is not None:
        identified = o.identified or declared_plant(o.plant, w.model.n_actuators, cfg.period)
        rig = RigDescription(
            w.model, cfg, dict(o.gains), identified, scene, scene.world.c2,
            w.cams.T_ee_c2, w.cams.T_ee_cube, w.cams.berry_tag, w.cams.T_base_tag, o.survey,
        )  # fmt: skip
        write_rig_files(w.recorder.folder, rig)
    return RenderedWorld(o.world, scene, vision, gripper, canes, o.survey)


#: How each world is built.
WORLDS: dict[WorldName, Callable[[WorldParts], HarvestWorld]] = {
    WorldName.TAGS: _tag_world,
    WorldName.BUSH: _rendered_world,
    WorldName.ROW: _rendered_world,
}


def _look(o: SimRigOptions, bush: Bush) -> RowLook | None:
    """The row's look of ``o`` (drawn from the bush's seed), None for the bush."""
    return RowLook.named(o.look or "random", bush.seed) if o.world is WorldName.ROW else None


def _bush_scene(
    bush: Bush,
    plant: ArmPlant,
    cams: SimCameras,
    clock: SimClock,
    recorder: FrameRecorder | None,
    look: RowLook | None = None,
) -> BushScene:
    """The rendered bush (in the row with ``look``), C1 registered on its base tag, the
    first C1 look merged into its map."""
    world = world_for(bush, cams, BASE_TAG_ID, look=look, c2_scale=C2_SCALE)
    scene = BushScene(world, BushMap(), bush, plant)
    if recorder is not None:
        scene.read_pair = recorder.wrap_pair(scene.pair, clock.now)
    T_base_c1 = register_c1(
        scene.c1_whole, cams.model(1), BASE_TAG_ID, cams.base_tag, cams.T_base_tag
    )
    scene.registered(invert(T_base_c1))
    scene.look()
    return scene


def _bush_vision(
    scene: BushScene, cams: SimCameras, grasp_offset: float, recorder: FrameRecorder | None
) -> BushVision:
    """The markerless vision: the cube and base tag in the rendered C1, the berries
    from the map and C2 (softarm.perception.bush_vision)."""
    c1, c2 = scene.frames()
    if recorder is not None:
        c1, c2 = recorder.wrap("c1", c1), recorder.wrap("c2", c2)
    m1, m2 = cams.model(1), scene.world.c2
    T_base_c1 = scene.c1().T_base_left
    cube = marker_body(cams.marker_body, cams.cube_marker)
    return BushVision(
        c1, c2, m1, m2, T_base_c1, cams.T_ee_c2, cams.T_ee_cube, cube, cams.berry_tag,
        grasp_offset, bush_map=scene.bush_map,
    )  # fmt: skip
