"""Issue 13 item 3: ``Gains.default_for(arm)`` uses the arm: the body radius of the
obstacle repulsion is the widest section's actuator radius + an actuator + a cane."""

from __future__ import annotations

import pytest

import softarm


def test_default_for_sizes_the_body_radius_from_the_arm() -> None:
    arm = softarm.SoftArm.blackberry()
    assert softarm.Gains.default_for(arm) == softarm.Gains()
    sections = list(arm.sections)
    s = sections[1]
    sections[1] = softarm.Section(
        radius=0.05,
        rest_length=s.rest_length,
        lower=s.lower,
        upper=s.upper,
        offset=s.offset,
        twist=s.twist,
    )
    wide = softarm.Gains.default_for(softarm.SoftArm(sections))
    assert wide.body_radius == pytest.approx(0.05 + 0.008 + 0.005, abs=1e-15)
    # Everything else is the preset.
    assert wide.replace(body_radius=softarm.Gains().body_radius) == softarm.Gains()
