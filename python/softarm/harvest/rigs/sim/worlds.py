"""The simulated rig's worlds built (:data:`WORLDS`, one builder per
:class:`~softarm.sim.world.WorldName`): the tag world, and the rendered bush and row with
their map, markerless vision, gripper on the true berries and canes fitted from C1."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import softarm
from softarm.checks import FloatArray
from softarm.harvest.control.stack import ControlStack
from softarm.harvest.machine.harvest_machine import HarvestMachine
from softarm.harvest.records.frame_files import FrameRecorder
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.rigs.replay.dry_run import (
    RigDescription,
    write_rig_files,
)
from softarm.harvest.rigs.sim.bush_world import BushGripper, BushScene, RenderedWorld
from softarm.harvest.rigs.sim.devices import SimClock, SimGripper
from softarm.harvest.rigs.sim.options import SimRigOptions, declared_plant
from softarm.harvest.rigs.sim.tag_world import TagWorld
from softarm.harvest.runs.cane_survey import CaneSurvey
from softarm.perception.bush_map import BushMap
from softarm.perception.bush_vision import BushVision
from softarm.perception.cane_source import use_cane_source
from softarm.perception.detector.choice import use_detector
from softarm.perception.self_filter import CANE_REACH
from softarm.sim.bush import Bush
from softarm.sim.plant import ArmPlant
from softarm.sim.render.row import row_canes
from softarm.sim.render.row_look import RowLook
from softarm.sim.render.world import world_for
from softarm.sim.rig_cameras import BASE_TAG_ID, SimCameras, sim_vision
from softarm.sim.world import World, WorldName
from softarm.vision.marker_body import marker_body
from softarm.vision.poses import invert
from softarm.vision.two_cameras import CameraVision, register_c1

__all__ = ["C2_SCALE", "WORLDS", "HarvestWorld", "WorldParts", "true_canes"]


class HarvestWorld(World, Protocol):
    """A :class:`~softarm.sim.world.World` the simulated rig harvests: its berry source
    run by the run policy (:class:`~softarm.harvest.rigs.sim.tag_world.TagWorld`,
    :class:`~softarm.harvest.rigs.sim.bush_world.RenderedWorld`)."""

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
    def scene(self) -> BushScene | None:
        """The rendered world's scene and map (C1's picture); None in the tag world."""
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
    #: The rig at rest as C1 sees it (softarm.perception.self_filter.rig_outline): the
    #: cane points seen only through it are left out of C1's fit; None keeps them.
    outline: FloatArray | None = None


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
    canes = scene.fit_canes(w.parts, CANE_REACH, w.outline)
    vision = _bush_vision(scene, w.cams, cfg.grasp_offset, w.recorder)
    gripper = BushGripper(
        scene, w.plant, vision, list(w.bush.berries), cfg.grasp_offset, cfg.grasp_workspace
    )
    if w.recorder is not None:
        identified = o.identified or declared_plant(o.plant, w.model.n_actuators, cfg.period)
        rig = RigDescription(
            w.model, cfg, dict(o.gains), identified, scene, scene.world.c2,
            w.cams.T_ee_c2, w.cams.T_ee_cube, w.cams.berry_tag, w.cams.T_base_tag,
            w.cams.marker_body, w.cams.cube_marker, o.survey,
        )  # fmt: skip
        write_rig_files(w.recorder.folder, rig)
    return RenderedWorld(o.world, scene, vision, gripper, canes, o.survey)


#: How each world is built.
WORLDS: dict[WorldName, Callable[[WorldParts], HarvestWorld]] = {
    WorldName.TAGS: _tag_world,
    WorldName.BUSH: _rendered_world,
    WorldName.ROW: _rendered_world,
}


def true_canes(o: SimRigOptions, bush: Bush) -> list[softarm.PolynomialCurve]:
    """Every cane of the world ``o`` harvests, as drawn: the bush's, and in the row the
    row's own too (they stand clear of the berries' approach corridors, not of the arm's
    sections, so the arm can touch them): the truth contacts are scored on."""
    look = _look(o, bush)
    row = [] if look is None else row_canes(bush, look)
    return [b.curve() for b in [*bush.branches, *row]]


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
    world.set_clock(clock.now)  # the row's motion blur: the arm's steps in sim time
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
        grasp_offset, bush_map=scene.bush_map, c2_unneeded=scene.c2_unneeded,
    )  # fmt: skip
