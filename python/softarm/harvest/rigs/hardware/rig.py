"""The hardware rig: the same state machine on the real devices, from a TOML config.

Devices are opened in the order of the bring-up (pressure outputs behind the safety
layer, the Arduino for gripper and ripeness sensor, both cameras); if one is missing
everything opened so far is vented and closed again and
:class:`~softarm.errors.HardwareUnavailableError` says which device and why.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import ExitStack
from dataclasses import dataclass

import numpy as np

from softarm._core import PolynomialCurve, Section, SoftArm
from softarm.calibration.result import Calibration
from softarm.checks import FloatArray
from softarm.config import Config
from softarm.errors import ConfigError, ParameterError
from softarm.hardware.arduino_devices import ArduinoGripper, ArduinoRipenessSensor
from softarm.hardware.clock import MonotonicClock
from softarm.hardware.pressure_map import ElongationMap
from softarm.hardware.protocols import PressureBank
from softarm.hardware.safety import SafePressureBank
from softarm.harvest.control.actuator import PressureMap
from softarm.harvest.control.stack import ControlInputs, build_control_stack
from softarm.harvest.machine.harvest_machine import HarvestMachine
from softarm.harvest.machine.interfaces import BerryTarget, Clock
from softarm.harvest.machine.states import FAULTS_THAT_STOP
from softarm.harvest.records.log import HarvestLog
from softarm.harvest.records.report import HarvestReport
from softarm.harvest.rigs.hardware.devices import DeviceDrivers, Devices
from softarm.harvest.rigs.hardware.stereo import stereo_camera
from softarm.harvest.runs.cane_survey import CaneSurvey
from softarm.harvest.runs.map_run import harvest_map
from softarm.harvest.runs.policy import finish_run, run_targets
from softarm.harvest_config import HarvestConfig
from softarm.identified_plant import IdentifiedPlant
from softarm.perception.bush_vision import BushVision
from softarm.perception.c1 import StereoC1
from softarm.perception.cane_source import use_cane_source
from softarm.perception.detector.choice import use_detector
from softarm.perception.self_filter import CANE_REACH, rig_outline, rig_parts
from softarm.perception_config import BerryMode
from softarm.vision.camera_model import camera_from_config
from softarm.vision.marker_body import marker_body
from softarm.vision.poses import invert
from softarm.vision.two_cameras import CameraVision

__all__ = ["HardwareRig", "MonotonicClock", "build_hardware_rig", "hardware_inputs"]


@dataclass
class HardwareRig:
    """The machine and the devices it runs on; ``close()`` vents and releases them."""

    machine: HarvestMachine
    devices: ExitStack
    #: C1 as the ``[perception]`` stereo source and its bush map; None: C1 alone.
    c1: StereoC1 | None = None
    #: The berries come from the map (``berries = "markerless"``), not from tags.
    markerless: bool = False
    #: C2's survey of the canes C1 fitted, flown at the start of :meth:`run`; None
    #: without perceived canes or with ``survey = false``.
    survey: CaneSurvey | None = None

    def close(self) -> None:
        """Vent the arm and release every device."""
        self.devices.close()

    def run(self, berries: int) -> HarvestReport:
        """Harvest ``berries``: the tags 10, 11, ... stuck to them (section IV-E), or
        with markerless perception at most that many of the map's ripe berries, by the
        loop the rendered bush runs (:func:`~softarm.harvest.runs.map_run.harvest_map`);
        the survey first, where there is one."""
        if self.survey is not None:
            self.survey.run()
        if not self.markerless or self.c1 is None:
            tags = [BerryTarget(10 + i) for i in range(berries)]
            return run_targets(self.machine.run_berry, tags, self.machine.log)
        report = HarvestReport()
        c1, machine = self.c1, self.machine
        report.berries = harvest_map(
            c1.look, c1.bush_map, machine.run_berry, berries, stop_on=FAULTS_THAT_STOP,
            on_look=lambda: machine.log_map(c1.bush_map),
        )  # fmt: skip
        return finish_run(report, machine.log)


def build_hardware_rig(
    config: Config,
    harvest: HarvestConfig | None = None,
    log: HarvestLog | None = None,
    identified: IdentifiedPlant | None = None,
    calibration: Calibration | None = None,
    canes: Sequence[PolynomialCurve] = (),
    devices: Devices | None = None,
    seed: int = 0,
) -> HardwareRig:
    """Open every device of ``config`` and wire the machine, tuned by ``harvest`` (default:
    the config's ``[harvest]``), on the control stack the simulator uses
    (:func:`~softarm.harvest.control.stack.build_control_stack`). With the ``identified`` plant
    (``[plant_model]``) the actuator predicts the regulators' lag, with their lead, and
    the loop corrects the motion still in flight (docs/control.md); without it the
    resolver's gain is bounded for the slowest plant (the defaults' 20 periods). The
    ``calibration`` (``--model``) replaces the configured arm and pressure map; the
    ``canes`` are avoided by planner, resolver and way check: with ``[perception]``
    (and none given) the ones fitted from C1's stereo at start, else none unless given.
    ``devices`` opens the devices (default: the real drivers; the dry run's replay
    them); ``seed`` is the planner's.

    Raises:
        HardwareUnavailableError: a device (or its driver) is absent.
        ConfigError: the calibration needed by the vision loop is missing.
        ParameterError: ``canes`` are given while ``[perception]`` asks for the survey,
            which refines the canes C1 fits (it was silently left out).
    """
    cfg = harvest or config.harvest
    cal = config.calibration
    if cal.T_C1_base is None or cal.T_C2_EE is None:
        raise ConfigError("calibration.T_C1_base and calibration.T_C2_EE must be set to harvest")
    if canes and config.perception is not None and config.perception.survey:
        raise ParameterError(
            "canes: given canes replace the ones C1 fits, which [perception] survey "
            "refines; set survey = false in [perception] to harvest with them"
        )
    inputs = hardware_inputs(config, identified, calibration, seed)
    dev = devices or DeviceDrivers()
    with ExitStack() as stack:
        clock = dev.clock()
        bank = _pressure_bank(config, dev.pressure_outputs(config, stack), clock, stack)
        link = dev.arduino(config, stack)
        c1 = _stereo_c1(config, dev, stack)
        parts = None
        if c1 is not None and not canes:
            parts = _rig_parts(config, cfg, inputs.model)
            canes = c1.fit_canes(parts, CANE_REACH, _rig_outline(config, inputs.model))
        vision = _vision(config, cfg, dev, stack, c1)
        markerless = _markerless(config, c1)
        control = build_control_stack(cfg, inputs, canes, bank, clock.now, markerless)
        machine = HarvestMachine(
            clock, vision, control.controller, control.actuator, ArduinoGripper(link),
            ArduinoRipenessSensor(link), inputs.model.n_actuators, cfg, log,
            planner=control.planner,
        )  # fmt: skip
        survey = None
        if c1 is not None and parts is not None and config.perception is not None:
            if config.perception.survey:
                survey = CaneSurvey(machine, control, c1, vision, parts, CANE_REACH)
        return HardwareRig(machine, stack.pop_all(), c1, markerless, survey)
    raise AssertionError("unreachable")  # pragma: no cover  (the with block returns)


def hardware_inputs(
    config: Config,
    identified: IdentifiedPlant | None = None,
    calibration: Calibration | None = None,
    seed: int = 0,
) -> ControlInputs:
    """The control stack's inputs of a hardware ``config``: its arm and channels unless
    a fitted ``calibration`` replaces them, the ``identified`` lag and play, its
    ``[gains]`` (``--gains`` merged in already), the planner's ``seed``."""
    ch = config.channels
    if calibration is None:
        model = SoftArm([Section(**vars(sec)) for sec in config.arm.sections])
        pressure_map: PressureMap = ElongationMap(ch.p_max, ch.metres_per_psi)
    else:
        model, pressure_map = calibration.arm, calibration.pressure_map(ch.p_max)
    return ControlInputs.of_plant(
        model, pressure_map, identified, gains=dict(config.gains.values), seed=seed
    )


def _pressure_bank(
    config: Config, outputs: PressureBank, clock: Clock, stack: ExitStack
) -> SafePressureBank:
    """The pressure ``outputs`` behind the safety layer, timed by ``clock``; ``stack``
    closes (vents) it."""
    ch = config.channels
    bank = SafePressureBank(
        outputs, ch.p_max, ch.max_rate_psi_per_s, ch.watchdog_timeout_s, clock.now
    )
    stack.callback(bank.close)
    return bank


def _stereo_c1(config: Config, devices: Devices, stack: ExitStack) -> StereoC1 | None:
    """C1 as the ``[perception]`` stereo source (its devices closed by ``stack``), its
    first view in the map; None without the table."""
    perception = config.perception
    if perception is None:
        return None
    use_detector(perception.detector)  # [perception] detector: read its weights now
    use_cane_source(perception.canes)  # [perception] canes: likewise
    T_base_c1 = invert(np.array(config.calibration.T_C1_base))
    stereo = stereo_camera(perception, T_base_c1)
    c1 = StereoC1(stereo, devices.stereo(perception, stack))
    c1.look()
    return c1


def _rig_parts(config: Config, cfg: HarvestConfig, model: SoftArm) -> FloatArray:
    """What C1 sees of the rig itself, left out of the canes it fits: the arm, its
    cube and (where the config places it) the base tag."""
    cal = config.calibration
    tag = None if cal.T_base_tag is None else np.array(cal.T_base_tag)
    body = marker_body(cal.marker_body, cal.marker_length)
    return rig_parts(model, cfg, np.array(cal.T_EE_cube), tag, body)


def _rig_outline(config: Config, model: SoftArm) -> FloatArray:
    """The rig as C1 sees it when it fits the canes: the arm vented, at rest."""
    cal = config.calibration
    body = marker_body(cal.marker_body, cal.marker_length)
    return rig_outline(model, np.zeros(model.n_actuators), np.array(cal.T_EE_cube), body)


def _vision(
    config: Config, cfg: HarvestConfig, devices: Devices, stack: ExitStack, c1: StereoC1 | None
) -> CameraVision:
    """Both cameras, opened and closed by ``stack``, and the vision loop on them: with
    ``c1`` the stereo source's left eye is C1, and the berries come from its map unless
    ``[perception]`` asks for tags."""
    cal = config.calibration
    frame1 = devices.c1_frames(config, stack, None if c1 is None else c1.left)
    model1 = camera_from_config(cal.c1, "c1") if c1 is None else c1.stereo.left
    body = marker_body(cal.marker_body, cal.marker_length)
    args = (
        frame1, devices.c2_frames(config, stack), model1, camera_from_config(cal.c2, "c2"),
        invert(np.array(cal.T_C1_base)), invert(np.array(cal.T_C2_EE)),
        np.array(cal.T_EE_cube), body, cal.berry_tag, cfg.grasp_offset,
    )  # fmt: skip
    if c1 is not None and _markerless(config, c1):
        return BushVision(*args, bush_map=c1.bush_map)
    return CameraVision(*args)


def _markerless(config: Config, c1: StereoC1 | None) -> bool:
    """Whether the berries come from C1's map (``[perception] berries = "markerless"``
    with a stereo source), not from their tags."""
    perception = config.perception
    return c1 is not None and perception is not None and perception.berries is BerryMode.MARKERLESS
