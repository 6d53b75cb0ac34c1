"""The control stack of a harvest rig, built once for the simulator and the hardware.

:func:`build_control_stack` wires the actuator (lag model, regulator lead, safety bank),
the controller (closed-loop and transport resolvers, canes, way check) and the planner
(IK on the model, clearance) from the same inputs in both worlds: only the devices
differ (pressure bank, cameras, gripper, ripeness sensor, clock), so behaviour tuned in
simulation is what the arm runs. ``--gains``, ``--model`` and ``--identified`` reach it
through :class:`ControlInputs` and nowhere else.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np

from softarm._core import (
    Gains,
    PolynomialCurve,
    Resolver,
    SoftArm,
    lead_gain,
    predicted_loop_alpha,
)
from softarm.config import GAIN_KEYS
from softarm.errors import ConfigError, ParameterError
from softarm.hardware.safety import SafePressureBank
from softarm.harvest.control.actuator import PressureMap, SafeActuator
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.controller import ResolverController
from softarm.harvest.control.ik import ModelIK, planning_resolver
from softarm.harvest.control.plant_model import MEASUREMENT_LAG_PERIODS
from softarm.harvest_config import HarvestConfig
from softarm.identified_plant import IdentifiedPlant

__all__ = ["ControlInputs", "ControlStack", "LagControl", "build_control_stack", "gains_over"]


class LagControl(StrEnum):
    """How the loop handles the plant's lag (docs/control.md, section 6): ``predictor``
    (a lag model of every command, its motion in flight taken out of the error) or
    ``bound`` (the gain bounded by the whole lag)."""

    PREDICTOR = "predictor"
    BOUND = "bound"


@dataclass(frozen=True)
class ControlInputs:
    """What tunes the control stack, the same in both worlds.

    ``model``: the controller's arm (``--model``'s fit, else the nominal or configured
    arm); ``pressure_map``: elongation to psi (the fit's, the config's channels, or None
    for the bank's own); ``lag_s`` and ``play_m``: the regulators' lag and play
    (``--identified``, else declared; ``lag_s`` None: unknown, the gain bounded for the
    slowest plant); ``gains``: keywords over every controller resolver's gains
    (``--gains``, ``[gains]``); ``lag_control``: "predictor" (a lag model of every
    command, its motion in flight taken out of the error) or "bound" (the gain bounded
    by the whole lag); ``joint_limit_gain``: the closed loop's γ; ``avoid_canes``: the
    canes repel the resolver and check its way; ``seed``: the planner's.
    """

    model: SoftArm
    pressure_map: PressureMap | None = None
    lag_s: float | None = None
    play_m: Any = 0.0
    gains: Mapping[str, Any] = field(default_factory=dict)
    lag_control: LagControl = LagControl.PREDICTOR
    joint_limit_gain: float | None = None
    avoid_canes: bool = True
    seed: int = 0

    def __post_init__(self) -> None:
        if self.lag_control not in LagControl._value2member_map_:
            raise ParameterError(
                f"lag_control = {self.lag_control!r}: must be 'predictor' or 'bound'"
            )
        object.__setattr__(self, "lag_control", LagControl(self.lag_control))

    @classmethod
    def of_plant(
        cls,
        model: SoftArm,
        pressure_map: PressureMap | None,
        plant: IdentifiedPlant | None,
        **options: Any,
    ) -> ControlInputs:
        """The inputs of an arm ``model`` on a ``plant`` as `softarm identify` measures
        it (its slowest channel's lag, its play bands; None: unknown), ``options`` the
        other fields. Both rigs build theirs here."""
        if plant is None:
            return cls(model, pressure_map, **options)
        play = np.asarray(plant.play_m)
        return cls(model, pressure_map, lag_s=plant.lag_s, play_m=play, **options)

    @property
    def predicts(self) -> bool:
        """Whether the loop runs on a lag model (a known lag, in predictor mode)."""
        return self.lag_control is LagControl.PREDICTOR and self.lag_s is not None


@dataclass
class ControlStack:
    """The actuator, controller and planner of a rig, and the model's clearance."""

    actuator: SafeActuator
    controller: ResolverController
    planner: ModelIK
    clearance: Clearance

    def know_canes(self, canes: Sequence[PolynomialCurve]) -> None:
        """From now on avoid ``canes`` (a refined map) instead: the planner's and the way
        check's clearance, and the controller's obstacles unless it avoids none. The
        canes known before stay the planner's fallback (:meth:`ModelIK.plan`), and a
        plan that falls back on them is followed avoiding them alone (:meth:`_follow`)."""
        c = self.clearance  # the stack's, shared by its planner and controller
        self.planner.fall_back_on(Clearance(c.arm, c.canes, c.offset), self._follow)
        c.canes = list(canes)
        self._follow(False)

    def _follow(self, fell_back: bool) -> None:
        """After each plan, the canes the loop keeps the arm from until the next one
        (the resolver's obstacles and the way check, unless the controller avoids
        none): those the plan cleared. A plan around the fallback's canes alone goes
        through a cane of the refined map, on the model; the way check would hold the
        arm on its planned way before that cane until the placement timed out."""
        fallback = self.planner.fallback
        self.controller.avoid(fallback if fell_back and fallback is not None else self.clearance)


def gains_over(base: Gains, values: Mapping[str, Any]) -> Gains:
    """``base`` with the gain keywords ``values`` over it.

    Raises:
        ConfigError: an unknown key or a value the resolver refuses, named.
    """
    for key in values:
        if key not in GAIN_KEYS:
            raise ConfigError(f"{key}: unknown gain (expected one of {', '.join(GAIN_KEYS)})")
    try:
        return base.replace(**values)
    except (ValueError, TypeError) as exc:
        raise ConfigError(str(exc)) from None


def build_control_stack(
    cfg: HarvestConfig,
    inputs: ControlInputs,
    canes: Sequence[PolynomialCurve],
    bank: SafePressureBank,
    now: Callable[[], float],
    markerless: bool = False,
) -> ControlStack:
    """The control stack on ``bank`` (behind its safety layer), timed by ``now``, with
    ``canes`` (the known obstacles, possibly none) avoided by planner and controller.

    The planner tries ``cfg.near_standoff`` first for berries fixed by their tags. A
    ``markerless`` harvest's fine positioning is closed on C2's detection of the berry,
    which needs the whole ``standoff`` to settle: nearer, C2 lost a berry in the row's
    sun and the grasp ended 8 mm off it (docs/harvest.md, "A nearer pre-grasp pose")."""
    actuator = _actuator(cfg, inputs, bank, now)
    # The model arm's gap to the known canes: the planner checks its plans with it, the
    # controller keeps the lagging arm's way to each command clear with it.
    clearance = Clearance(inputs.model, canes, cfg.grasp_offset)
    controller = _controller(cfg, inputs, canes, clearance, actuator)
    planner = ModelIK(
        planning_resolver(inputs.model), cfg, seed=inputs.seed, clearance=clearance,
        band=cfg.plan_band, near_standoff=0.0 if markerless else cfg.near_standoff,
    )  # fmt: skip
    return ControlStack(actuator, controller, planner, clearance)


def _sensor_lag(cfg: HarvestConfig) -> float:
    """One period of measurement lag behind the regulators (an over-estimate, on
    purpose); arrival (``in_flight``) reads the regulators alone."""
    return MEASUREMENT_LAG_PERIODS * cfg.period


def _actuator(
    cfg: HarvestConfig, inputs: ControlInputs, bank: SafePressureBank, now: Callable[[], float]
) -> SafeActuator:
    """The safety layer's actuator, with the lag model and the regulators' lead when
    the loop predicts."""
    lag = inputs.lag_s if inputs.predicts else None
    return SafeActuator(
        bank,
        inputs.pressure_map,
        lag=None if lag is None else (lag, cfg.period),
        now=now,
        sensor_lag_s=_sensor_lag(cfg),
        lead=0.0 if lag is None else lead_gain(lag, cfg.period, cfg.lead_cap),
        play_m=inputs.play_m if lag is not None else 0.0,
    )


def _controller(
    cfg: HarvestConfig,
    inputs: ControlInputs,
    canes: Sequence[object],
    clearance: Clearance,
    actuator: SafeActuator,
) -> ResolverController:
    """The closed-loop resolver and the transport one.

    With the lag model the closed loop on the berry is the lag-free iteration (a Smith
    predictor) at a gain cut as the lag grows (``predicted_loop_alpha``). Following a
    placement plan keeps the gain bounded by the whole lag, without the prediction: on
    a slow plant with play the predictor's gain swung the arm into a cane early in the
    move (docs/control.md, section 6). Without the model the bound is used throughout;
    an unknown lag is bounded for the slowest plant (the defaults' lag periods)."""

    def hybrid(gains: Gains) -> Resolver:
        if inputs.joint_limit_gain is not None:
            gains = gains.replace(hybrid_gamma=inputs.joint_limit_gain)
        # The repulsion measures the body the way check and the contact gaps measure.
        gains = gains_over(gains, inputs.gains)
        return Resolver(inputs.model, mode="hybrid", gains=gains, body=clearance.body)

    lag = inputs.lag_s
    bounded = hybrid(Gains() if lag is None else Gains.for_lag(lag, cfg.period))
    if not inputs.predicts:
        return _with_canes(bounded, None, None, inputs, canes, clearance)
    assert lag is not None  # predicts: a known lag
    alpha = predicted_loop_alpha(lag + _sensor_lag(cfg))
    loop = hybrid(Gains().replace(hybrid_alpha=alpha))
    return _with_canes(loop, lambda: actuator.plant_q, bounded, inputs, canes, clearance)


def _with_canes(
    resolver: Resolver,
    plant_q: Callable[[], Any] | None,
    transport: Resolver | None,
    inputs: ControlInputs,
    canes: Sequence[object],
    clearance: Clearance,
) -> ResolverController:
    """The controller, the canes inside its steps and its way check unless
    ``avoid_canes`` is off."""
    avoid = inputs.avoid_canes
    return ResolverController(
        resolver, canes if avoid else (), plant_q, transport, clearance if avoid else None
    )
