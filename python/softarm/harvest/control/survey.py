"""Where the arm takes C2 to look at the bush, two by two (the cane survey).

C1's stereo pair leaves part of each cane without depth: the pixels hidden from its
right eye, and those its matcher cannot place (docs/perception.md, Limits). C2, on the
arm, sees the bush from nearer and from another side. Two C2 frames taken a few
centimetres apart along C2's own x axis are a stereo pair
(:func:`softarm.perception.cane_views.view_pair_points`) that fills those gaps.

The pairs are planned on the controller's model: random configurations whose C2
sees the bush (the bush lies at the edge of the arm's reach, and few configurations
face it: about one in a thousand), each with a partner that moves C2 sideways by
the baseline with its pointing kept (the placement planner's inverse kinematics,
:meth:`softarm.harvest.control.ik.ModelIK.solve`); every view and every ramp between them
clear of the canes known so far. The true arm is a few % off the model; that moves
where the views are taken, not what they measure, for the views' poses come from the
tracked cube (eq. 22).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softarm.checks import FloatArray
from softarm.harvest.control.ik import ModelIK

__all__ = ["SurveyPlan", "SurveySettings", "plan_survey"]


@dataclass(frozen=True)
class SurveySettings:
    """``pairs``: how many pairs of views; ``baseline``: C2's sideways move (m) within a
    pair; ``distance``: nearest and farthest (m) of C2 from the bush's centre;
    ``max_angle``: largest angle (degrees) of the centre off C2's optical axis (C2
    sees about 45° to each side); ``spread``: least distance (m) between the first
    views of two pairs; ``margin``: least gap (m) of the model arm to the known canes
    at each view; ``samples``, ``seed``: the random configurations drawn."""

    pairs: int = 3
    baseline: float = 0.04
    distance: tuple[float, float] = (0.12, 0.5)
    max_angle: float = 40.0
    spread: float = 0.06
    margin: float = 0.025
    samples: int = 60000
    seed: int = 0


@dataclass(frozen=True)
class SurveyPlan:
    """The configurations (elongations, m) of each pair's two views, in order."""

    pairs: list[tuple[FloatArray, FloatArray]]


def plan_survey(
    ik: ModelIK,
    q: FloatArray,
    home: FloatArray,
    T_ee_camera: FloatArray,
    centre: FloatArray,
    settings: SurveySettings | None = None,
) -> SurveyPlan:
    """Pairs of configurations of ``ik.arm`` from which the camera at ``T_ee_camera``
    (end-effector frame) sees the bush around ``centre`` (base frame, m), flown in
    order from ``q`` and left for ``home`` (see the module docstring). Each view
    keeps ``settings.margin`` from the known canes on the model; each straight ramp,
    from ``q`` or the previous pair to the first view, to the second, and from the
    second to ``home``, keeps the planner's ramp margin (:meth:`~softarm.harvest.control.ik.
    ModelIK.clear`). Fewer than ``settings.pairs``, maybe none, when the arm cannot
    take the camera there so."""
    s = settings or SurveySettings()
    T_ee_camera = np.asarray(T_ee_camera, np.float64)
    pairs: list[tuple[FloatArray, FloatArray]] = []
    firsts: list[FloatArray] = []
    last = np.asarray(q, np.float64)
    for first in _facing(ik, T_ee_camera, centre, s):
        place = (np.asarray(ik.arm.forward(first)) @ T_ee_camera)[:3, 3]
        if any(np.linalg.norm(place - p) < s.spread for p in firsts):
            continue
        if not (_clear(ik, first, s.margin) and ik.clear(last, first)):
            continue
        second = _partner(ik, first, T_ee_camera, s)
        if second is None or not ik.clear(second, home):
            continue
        pairs.append((first, second))
        firsts.append(place)
        last = second
        if len(pairs) == s.pairs:
            break
    return SurveyPlan(pairs)


def _facing(
    ik: ModelIK, T_ee_camera: FloatArray, centre: FloatArray, s: SurveySettings
) -> list[FloatArray]:
    """Random configurations whose camera sees ``centre`` within ``max_angle`` of its
    axis from inside ``distance``, the most squarely first."""
    arm = ik.arm
    lower, upper = np.asarray(arm.lower), np.asarray(arm.upper)
    qs = np.random.default_rng(s.seed).uniform(lower, upper, size=(s.samples, lower.size))
    cameras = np.asarray(arm.forward_batch(qs)) @ T_ee_camera
    to_centre = np.asarray(centre, np.float64) - cameras[:, :3, 3]
    distance = np.linalg.norm(to_centre, axis=1)
    cos = np.einsum("ij,ij->i", cameras[:, :3, 2], to_centre) / np.maximum(distance, 1e-9)
    near, far = s.distance
    ok = (cos >= np.cos(np.radians(s.max_angle))) & (distance >= near) & (distance <= far)
    return [qs[i] for i in np.flatnonzero(ok)[np.argsort(-cos[ok])]]


def _partner(
    ik: ModelIK, first: FloatArray, T_ee_camera: FloatArray, s: SurveySettings
) -> FloatArray | None:
    """The configuration with the camera ``baseline`` along its own x axis (either
    way) from where it is at ``first``, its pointing kept, clear of the canes on
    the model and on the ramp from ``first``; None when the model has none."""
    T = np.asarray(ik.arm.forward(first))
    side = (T @ T_ee_camera)[:3, 0]
    for sign in (1.0, -1.0):
        moved = T.copy()
        moved[:3, 3] += sign * s.baseline * side
        for second in ik.solve(first, moved, sample=False):
            if _clear(ik, second, s.margin) and ik.clear(first, second, 6):
                return second
    return None


def _clear(ik: ModelIK, q: FloatArray, margin: float) -> bool:
    return ik.clearance is None or ik.clearance.gap(q) >= margin
