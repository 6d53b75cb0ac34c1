"""The cube tracking experiment's figures over several frames of one pose
(softarm.experiments.cube_tracking.over_frames): each frame's error, the error of the
frames' mean position, and each pose's spread."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.experiments.cube_tracking import Pose, _with_frames, main, over_frames


def test_the_mean_of_frames_cancels_an_error_that_changes_sign() -> None:
    truth = np.array([0.1, 0.2, 1.0])
    offsets = np.array([[1e-3, 0, 0], [-1e-3, 0, 0], [0, 2e-3, 0]])
    frames = list(truth + offsets)
    pose = _with_frames(Pose(1.0, 30.0, 1.0, True), frames, truth)
    assert pose.frame_errors == pytest.approx((1.0, 1.0, 2.0))
    assert pose.mean_error == pytest.approx(2.0 / 3.0)  # (0, 2/3 mm, 0)
    figures = over_frames([pose, _with_frames(Pose(None, 30.0, 1.0, False), [], truth)])
    assert figures["frames_found"] == 3
    assert figures["median_frame_mm"] == pytest.approx(1.0)
    assert figures["median_mean_of_frames_mm"] == pytest.approx(2.0 / 3.0)
    assert figures["median_spread_mm"] == pytest.approx(1.0)


def test_a_pose_found_in_no_frame_keeps_no_frame_figures() -> None:
    pose = _with_frames(Pose(None, 45.0, 0.5, False), [], np.zeros(3))
    assert pose.frame_errors == () and pose.mean_error is None
    assert np.isnan(over_frames([pose])["median_mean_of_frames_mm"])


def test_frames_below_one_is_refused_naming_the_option(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["460", "--frames", "0"])
    assert "--frames" in capsys.readouterr().err
