"""A corrupt camera frame (VisionError from the detector's frame check) faults the berry
being harvested (vented, logged) and the run goes on; it used to escape the machine's
fault handling and end the whole run with a traceback."""

from __future__ import annotations

import numpy as np

from softarm.harvest import BerryTarget, FaultReason, HarvestState
from softarm.harvest.machine.states import FAULTS_THAT_STOP
from softarm.harvest.runs.policy import run_targets
from softarm.vision import CameraModel, MarkerDetector

from .fakes import make_rig


def test_corrupt_frame_faults_the_berry_and_the_run_goes_on() -> None:
    rig = make_rig()
    detector, camera = MarkerDetector(), CameraModel.ideal(900.0, 640, 480)
    track = rig.tracker.track
    corrupt = np.zeros((480, 640), np.float32)  # a frame of the wrong type, as a bad driver

    def track_with_a_corrupt_frame(time: float) -> np.ndarray | None:
        if 1.0 <= time < 1.2 and rig.locator.selected == 1:
            detector.detect(corrupt, camera)  # raises VisionError, like CameraVision.track
        return track(time)

    rig.tracker.track = track_with_a_corrupt_frame  # type: ignore[method-assign]
    report = run_targets(rig.machine.run_berry, [BerryTarget(1), BerryTarget(2)], rig.machine.log)
    first, second = report.berries
    assert first.fault is FaultReason.VISION_ERROR
    assert first.final_state is HarvestState.FAULT
    assert FaultReason.VISION_ERROR not in FAULTS_THAT_STOP
    assert report.stopped is None and second.harvested
    assert any("vision_error" in v.reason for v in rig.bank.vent_log)
    fault = next(r for r in rig.machine.log.records if r["kind"] == "fault")
    assert fault["reason"] == "vision_error" and "VisionError" in fault["detail"]
