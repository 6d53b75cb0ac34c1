"""The markerless harvest in the rendered worlds (``--world bush`` and ``row``): the cameras are the
rendered C1 stereo pair and C2, the berries to pick come from the bush map (ripe ones
found in C1 without tags), and the canes given to the planner, the resolver and the
clearance checks are the ones fitted from C1. The true bush serves only the ground
truth: the gripper's catch, the contacts, and the report's errors.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from softarm._core import PolynomialCurve
from softarm.checks import FloatArray
from softarm.errors import ParameterError
from softarm.harvest.control.stack import ControlStack
from softarm.harvest.machine.harvest_machine import HarvestMachine
from softarm.harvest.machine.interfaces import BerryTarget
from softarm.harvest.machine.states import FAULTS_THAT_STOP
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.rigs.sim.devices import SimGripper
from softarm.harvest.runs.cane_survey import CaneSurvey
from softarm.harvest.runs.map_run import harvest_map
from softarm.harvest.runs.policy import finish_run
from softarm.perception.bush_map import BushMap, MappedBerry
from softarm.perception.bush_vision import BushVision
from softarm.perception.c1 import Pair, StereoC1
from softarm.perception.cane_metrics import cane_map_error
from softarm.perception.overlay import draw_bush_map
from softarm.perception.self_filter import CANE_REACH
from softarm.sim.bush import Berry, Bush
from softarm.sim.plant import ArmPlant
from softarm.sim.render.world import RenderedBush, arm_sections, polyline_sections
from softarm.sim.world import WorldName
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["BushGripper", "BushScene", "RenderedWorld", "draw_arm", "harvest_bush"]

#: A mapped berry is the true berry nearest it within this distance (m), for the
#: ground truth only.
TRUTH_MATCH = 0.03


def draw_arm(world: RenderedBush, plant: ArmPlant) -> None:
    """Draw the TRUE arm (the plant's state) in the world: arcs for the constant-
    curvature plant, the rod's centre line for the Cosserat one."""
    if hasattr(plant, "centreline") and hasattr(plant, "centreline_sections"):
        sections = polyline_sections(
            plant.centreline(), plant.centreline_sections(), plant.arm.n_sections
        )
    else:
        sections = arm_sections(plant.arm, plant.q())
    world.set_arm(sections, plant.pose())


@dataclass
class BushScene:
    """The rendered world, the map perception builds of it, and the true bush."""

    world: RenderedBush
    bush_map: BushMap
    bush: Bush
    plant: ArmPlant
    #: C1 as the rig knows it: the calibrated pair, placed in the base frame by the
    #: base-tag registration (eq. 22), as the cube tracking places it. The world's own
    #: C1 pose is the truth, which only the renderer uses.
    stereo: StereoCamera | None = None
    #: The registration's base pose in C1 (set by :meth:`registered`).
    T_C1_base: FloatArray | None = None
    #: C1's stereo source: :meth:`pair` unless a recorder wraps it.
    read_pair: Callable[[], Pair] | None = None
    _drawn: bytes = b""

    def _draw(self) -> None:
        """Draw the arm as it is, unless it is drawn so already (C1 and C2 read the
        same control period's state)."""
        key = self.plant.q().tobytes() + self.plant.pose().tobytes()
        if key != self._drawn:
            draw_arm(self.world, self.plant)
            self._drawn = key

    def registered(self, T_C1_base: FloatArray) -> None:
        """Place C1 where the registration found it: ``T_C1_base`` (the base in C1), as
        the hardware configuration keeps it, inverted as the hardware rig inverts it,
        so that a recorded run replays on the hardware path bit for bit."""
        self.T_C1_base = np.array(T_C1_base, dtype=float)
        self.stereo = replace(self.world.stereo, T_base_left=invert(self.T_C1_base))

    def c1(self) -> StereoCamera:
        """C1 as the rig knows it (after :meth:`registered`)."""
        if self.stereo is None:
            raise ParameterError("the bush scene's C1 is not registered yet")
        return self.stereo

    def pair(self) -> Pair:
        """C1's stereo pair now, with the arm drawn where it truly is."""
        self._draw()
        left, right = self.world.c1()
        return left.colour, right.colour

    def stereo_c1(self) -> StereoC1:
        """C1 as the hardware rig has it: the registered pair, its source, the map."""
        return StereoC1(self.c1(), self.read_pair or self.pair, self.bush_map)

    def look(self) -> int:
        """One C1 stereo view merged into the map (:meth:`StereoC1.look`, as on the
        arm); the number of berries new to it."""
        return self.stereo_c1().look()

    def fit_canes(
        self, rig_parts: FloatArray, reach: float, outline: FloatArray | None = None
    ) -> list[PolynomialCurve]:
        """The canes fitted from one C1 stereo view, without what is the rig's own
        (:meth:`StereoC1.fit_canes`, as on the arm: a fit that comes within SELF_MARGIN
        of ``rig_parts``, the robot seen by its own camera, or lies wholly beyond
        ``reach`` of the base is left out; the points seen only through the rig's
        ``outline`` before the fit); the map keeps them."""
        return self.stereo_c1().fit_canes(rig_parts, reach, outline)

    def frames(self) -> tuple[Callable[[float], np.ndarray], Callable[[float], np.ndarray]]:
        """C1's left eye and C2 as ``(time) -> image`` with the arm drawn as it is."""

        def c1(t: float) -> np.ndarray:
            # The window around the cube; the cube is all the tracking looks for in C1.
            self._draw()
            return self.world.cube_window(self.plant.pose() @ self.world.T_ee_cube)

        def c2(t: float) -> np.ndarray:
            self._draw()
            return self.world.c2_frame().colour

        return c1, c2

    def c2_unneeded(self, t: float) -> None:
        """C2's frame at ``t`` not taken (no fix needed): the row's camera model gives
        its number away (:meth:`~softarm.sim.render.row_camera.RowCameras.skip`)."""
        if self.world.effects is not None:
            self.world.effects.skip("c2")

    def c1_whole(self, t: float) -> np.ndarray:
        """C1's whole left image with the arm as it is (registration finds the base tag
        in it)."""
        self._draw()
        return self.world.c1_left().colour

    def picture(self) -> np.ndarray:
        """C1's left image now, with the map's berries and fitted canes drawn on it."""
        return draw_bush_map(self.c1_whole(0.0), self.bush_map, self.c1())

    def c1_shares(self, tags: list[int]) -> list[float]:
        """The visible share in C1's left eye (ground truth) of each true berry of
        ``tags``, with the arm as it is: at the end of a harvest home, where C1 looks
        from (what C1 had to find a berry by; C2 places only fruit C1 glimpsed)."""
        if not tags:
            return []
        self._draw()
        shares = self.world.berry_shares()
        return [round(shares[t], 3) for t in tags]

    def truth_of(self, berry_id: int) -> Berry | None:
        """The true berry (still on the bush or not) a map entry stands for, or None."""
        entry = self.bush_map.get(berry_id)
        if entry is None:
            return None
        near = min(
            self.bush.berries, key=lambda b: float(np.linalg.norm(b.position - entry.position))
        )
        return near if np.linalg.norm(near.position - entry.position) <= TRUTH_MATCH else None


class BushGripper(SimGripper):
    """:class:`SimGripper` whose selected berry is a map entry: it closes on the true
    berry that entry stands for (ground truth, :meth:`BushScene.truth_of`)."""

    def __init__(
        self,
        scene: BushScene,
        plant: ArmPlant,
        vision: object,
        on_bush: list[Berry],
        offset: float,
        workspace: float,
    ) -> None:
        super().__init__(plant, vision, on_bush, offset, workspace)
        self.scene = scene

    def _berry(self, tag_id: int) -> Berry | None:
        truth = self.scene.truth_of(tag_id)
        return truth if truth is not None and truth in self.on_bush else None

    def open(self) -> None:
        """Open (:meth:`SimGripper.open`); a berry delivered leaves the rendered bush
        too, and with it what it hid from the cameras."""
        delivered = len(self.delivered)
        super().open()
        for tag in self.delivered[delivered:]:
            self.scene.world.remove_berry(tag)


def harvest_bush(
    scene: BushScene,
    run_berry: Callable[[BerryTarget], BerryResult],
    on_berry: Callable[[int, BerryResult], None] | None = None,
    on_look: Callable[[], None] | None = None,
) -> HarvestReport:
    """Pick the map's ripe berries one by one (:func:`~softarm.harvest.runs.map_run.
    harvest_map`, the loop the arm runs), each result judged against the true bush;
    ``on_look()`` after each C1 look (the rig logs the map)."""
    report = HarvestReport()
    index: dict[int, int] = {}  # map berry -> its place in the report (a retry replaces)

    def judged(entry: MappedBerry, result: BerryResult) -> None:
        truth = scene.truth_of(entry.id)
        result.ripe = None if truth is None else bool(truth.ripeness >= 0.5)
        if truth is not None:
            result.localisation_error_mm = 1000.0 * float(
                np.linalg.norm(entry.position - truth.position)
            )
        if entry.id in index:  # the berry's last attempt stands, as in the tag world
            report.berries[index[entry.id]] = result
        else:
            index[entry.id] = len(report.berries)
            report.berries.append(result)
        if on_berry is not None:
            on_berry(index[entry.id], result)

    rounds = len(scene.bush.berries) + 8
    harvest_map(
        scene.look, scene.bush_map, run_berry, rounds, judged, stop_on=FAULTS_THAT_STOP,
        on_look=on_look,
    )  # fmt: skip
    return report


def _bush_extra(scene: BushScene, delivered: list[int], name: WorldName) -> dict[str, object]:
    ripe = [b for b in scene.bush.berries if b.ripeness >= 0.5]
    picked = {b.tag_id: b for b in scene.bush.berries if b.tag_id in delivered}
    mapped = {t.tag_id for e in scene.bush_map.berries if (t := scene.truth_of(e.id)) is not None}
    unmapped = [b.tag_id for b in ripe if b.tag_id not in mapped]
    return {
        "world": name.value,
        "ripe_in_reach": len(ripe),
        "ripe_harvested": sum(b.ripeness >= 0.5 for b in picked.values()),
        "unripe_picked": sum(b.ripeness < 0.5 for b in picked.values()),
        "unripe_left": sum(b.ripeness < 0.5 and b.tag_id not in picked for b in scene.bush.berries),
        "ripe_never_mapped": len(unmapped),
        "ripe_never_mapped_c1_share": scene.c1_shares(unmapped),
        "cane_map": {
            k: v
            for k, v in cane_map_error(scene.bush_map.canes, scene.world.canes()).items()
            if k in ("median_mm", "p95_mm", "coverage", "precision", "length_m")
        },
    }


@dataclass
class RenderedWorld:
    """The :class:`~softarm.sim.world.World` the renderer draws (the bush, or the bush in
    the daylight row): the markerless vision, the gripper closing on the true berry a
    map entry stands for, the canes fitted from C1."""

    name: WorldName
    scene: BushScene
    vision: BushVision
    gripper: BushGripper
    canes: list[PolynomialCurve]
    #: Whether C2 surveys the canes C1 fitted before the first berry.
    surveyed: bool = True

    def survey(
        self, machine: HarvestMachine, stack: ControlStack, parts: FloatArray
    ) -> CaneSurvey | None:
        """C2's survey of the canes C1 fitted (the rig's own ``parts`` left out), as the
        hardware flies it; None with the survey off."""
        if not self.surveyed:
            return None
        c1 = self.scene.stereo_c1()
        return CaneSurvey(machine, stack, c1, self.vision, parts, CANE_REACH)

    def known_canes(self) -> Sequence[PolynomialCurve]:
        """The canes fitted from C1 (and the survey's refit, which goes to the stack)."""
        return self.canes

    def truth_of(self, berry_id: int) -> Berry | None:
        """The true berry the map entry ``berry_id`` stands for (:meth:`BushScene.truth_of`)."""
        return self.scene.truth_of(berry_id)

    def report_extra(self) -> dict[str, object]:
        """The world's ripe and unripe counts, what the map never placed, the cane map's
        error against the true canes."""
        return _bush_extra(self.scene, self.gripper.delivered, self.name)

    def close(self) -> None:
        """Free the renderer's OpenGL contexts."""
        self.scene.world.close()

    def harvest(
        self, machine: HarvestMachine, on_berry: Callable[[int, BerryResult], None] | None
    ) -> HarvestReport:
        """The map's ripe berries, by the loop the arm runs (:func:`harvest_bush`), the
        map logged after each look; the run finished by the run policy."""
        scene = self.scene
        report = harvest_bush(
            scene, machine.run_berry, on_berry, on_look=lambda: machine.log_map(scene.bush_map)
        )
        report.extra.update(self.report_extra())
        return finish_run(report, machine.log)
