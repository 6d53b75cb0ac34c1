"""The full simulated harvest: bush → synthetic cameras → vision → fusion → resolver →
safety layer → simulated pneumatic arm, on a simulated clock.

:func:`build_sim_rig` wires it; :meth:`SimRig.run` harvests every berry of the bush and
returns the report with ground-truth errors and the arm's clearance to the canes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

import softarm
from softarm.config import ChannelsConfig
from softarm.errors import ParameterError
from softarm.hardware import SafePressureBank, SimulatedPressureBank
from softarm.hardware.pressure_map import ElongationMap
from softarm.harvest.control.actuator import PressureMap
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.stack import ControlInputs, build_control_stack
from softarm.harvest.machine.harvest_machine import HarvestMachine
from softarm.harvest.machine.interfaces import Controller
from softarm.harvest.records.frame_files import FrameRecorder
from softarm.harvest.records.log import HarvestLog
from softarm.harvest.records.rate import rate_record
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.rigs.replay.dry_run import (
    BERRY_STATES,
    COMMANDS,
    CommandTap,
    RecordedSensor,
    berry_outcome,
)
from softarm.harvest.rigs.sim.bush_world import BushScene
from softarm.harvest.rigs.sim.devices import ArmWatch, SimClock, SimGripper
from softarm.harvest.rigs.sim.options import SimRigOptions, declared_plant, default_cameras
from softarm.harvest.rigs.sim.worlds import WORLDS, HarvestWorld, WorldParts, true_canes
from softarm.harvest.runs.cane_survey import CaneSurvey
from softarm.perception.self_filter import rig_outline, rig_parts
from softarm.sim.arm import SimulatedArm
from softarm.sim.bush import Bush
from softarm.sim.plant import ArmPlant
from softarm.sim.rig_cameras import SimCameras
from softarm.sim.world import WorldName
from softarm.units import MAX_PSI
from softarm.vision.marker_body import check_marker_body, marker_body
from softarm.vision.two_cameras import CameraVision

__all__ = ["SimRig", "build_sim_rig", "control_inputs", "sim_bush"]


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
        return self.world.scene

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
    canes = true_canes(o, bush)  # the truth: contacts are scored on it
    watch = _watch(o, plant, canes)
    clock = SimClock([plant.advance, watch.sample])
    bank = _bank(plant, clock, recorder)
    body = marker_body(cams.marker_body, cams.cube_marker)
    parts = rig_parts(model, cfg, cams.T_ee_cube, cams.T_base_tag, body)
    # C1 fits the canes with the arm vented, at rest.
    outline = rig_outline(model, np.zeros(model.n_actuators), cams.T_ee_cube, body)
    world = WORLDS[o.world](
        WorldParts(o, bush, canes, plant, model, cams, parts, clock, recorder, outline)
    )
    stack = build_control_stack(
        cfg, control_inputs(o, model), list(world.known_canes()), bank, clock.now,
        markerless=o.world is not WorldName.TAGS,
    )  # fmt: skip
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
