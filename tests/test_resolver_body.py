"""Issue 27 item 2: the resolver's obstacle repulsion measures a ``Body``, piece by piece:
by default the arm's own (``Body.for_arm(arm, 0.0)``), or the one it is given (the
harvest's, the same its ``Clearance`` measures)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import softarm
from softarm import Gains, InputError, ParameterError, Resolver, ShapeError, SoftArm
from softarm._core import Body

ARM = SoftArm.blackberry()


def test_the_default_body_is_the_arms() -> None:
    assert Resolver(ARM).body == Body.for_arm(ARM, 0.0)
    sections = list(ARM.sections)
    s = sections[1]
    sections[1] = softarm.Section(
        radius=0.05,
        rest_length=s.rest_length,
        lower=s.lower,
        upper=s.upper,
        offset=s.offset,
        twist=s.twist,
    )
    wide = SoftArm(sections)
    body = Resolver(wide).body
    assert body.section_radii[1] == pytest.approx(0.05 + softarm._core.ACTUATOR_RADIUS)
    # The gains no longer carry a body: every arm's resolver has the same defaults.
    assert Resolver(wide).gains == Gains()
    assert Gains().obstacle_radius == softarm._core.CANE_RADIUS


def test_a_given_body_is_measured_and_pickled() -> None:
    body = Body.for_arm(ARM, 0.03)
    res = Resolver(ARM, "hybrid", body=body)
    assert res.body == body
    back = pickle.loads(pickle.dumps(res))
    assert back.body == body and back.gains == res.gains and back.mode == "hybrid"
    # A cane 45 mm off the end effector's axis, 3 cm ahead of its frame: within the
    # influence distance (2 cm) of the gripper reaching the grasp point only.
    q = np.full(9, 0.0166)
    pose = ARM.forward(q)
    z, x = pose[:3, 2], pose[:3, 0]
    c = pose[:3, 3] + 0.03 * z + 0.045 * x
    y = np.cross(z, x)
    cane = softarm.Segment(c - 0.1 * y, c + 0.1 * y)
    g = Gains(lag_periods=0.0, influence_distance=0.02)
    short = Resolver(ARM, "hybrid", g).step(q, pose, obstacles=[cane])
    long = Resolver(ARM, "hybrid", g, body).step(q, pose, obstacles=[cane])
    assert short.clearance == np.inf
    gap = body.gap(ARM, q, [cane], softarm._core.CANE_RADIUS)
    assert gap == pytest.approx(0.015, abs=1e-9)
    assert long.clearance == pytest.approx(gap, abs=1e-12)
    assert np.linalg.norm(long.q - q) > 1e-7


def test_a_wrong_body_is_a_typed_error_naming_it() -> None:
    with pytest.raises(ShapeError, match="body"):
        Resolver(ARM, body=Body([0.03, 0.03], 0.025, 0.0, 0.0))
    with pytest.raises(InputError, match="body"):
        Resolver(ARM, body="wide")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="body_radius"):
        Gains(body_radius=0.04)  # the field is gone: the body is the resolver's
