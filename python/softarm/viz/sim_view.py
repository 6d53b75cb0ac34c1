"""A live rerun view of the simulated harvest (``softarm harvest --sim --view``).

:func:`attach` hooks a :class:`SimView` onto a built :class:`~softarm.harvest.rigs.sim.rig.
SimRig` without changing how it runs: the simulated clock's ``on_advance`` callbacks (the
same hook the plant and the cane watch use) draw the TRUE arm after every time step, and
the cameras' frame functions and the marker detector are wrapped to pass each image and
its detections through. Everything goes on one timeline, the simulated time:

* ``world/canes`` (the cane curves), ``world/berries`` (the berries still on the bush,
  labelled by tag; the selected one highlighted);
* ``world/arm/true``: the plant's arm (the truth the cameras see) and its gripper;
* ``world/c1/image``, ``world/c2/image``: both camera images, as pinhole cameras placed
  in the scene, with the detected markers outlined and labelled by id;
* ``errors/true_gap_mm``: the true arm's clearance to the canes; ``errors/
  true_grasp_mm``: the true grasp point's distance to the selected berry;
* and the run-log records (model arm, estimates, state machine, measured errors) through
  :class:`~softarm.viz.records.RecordLogger`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softarm.errors import ParameterError
from softarm.viz.layout import harvest_blueprint
from softarm.viz.records import ArmDrawer, RecordLogger
from softarm.viz.rerun_sdk import TIMELINE, close_recording, open_recording, require_rerun
from softarm.viz.scene import log_berries, log_canes

if TYPE_CHECKING:
    from softarm.harvest.rigs.sim.rig import SimRig

__all__ = ["SimView", "attach"]


class SimView:
    """Streams a :class:`SimRig` to ``stream``; see the module docstring.

    ``image_every``: log every n-th frame of each camera (1: all of them); the frames are
    JPEG-compressed (``jpeg_quality``) so a recording of a whole bush stays small.
    """

    def __init__(
        self,
        rig: SimRig,
        stream: Any,
        image_every: int = 1,
        jpeg_quality: int = 80,
    ) -> None:
        if int(image_every) < 1:
            raise ParameterError(f"image_every must be >= 1, got {image_every!r}")
        self.rr = rr = require_rerun()
        self.rig, self.stream = rig, stream
        self.image_every, self.jpeg_quality = int(image_every), int(jpeg_quality)
        #: Streams to a spawned viewer (which the user may close before the end).
        self.viewer = False
        offset = rig.machine.config.grasp_offset
        self.records = RecordLogger(stream, rr, rig.model, offset)
        self._drained = 0
        self._frames = {1: 0, 2: 0}
        self._frame_time = {1: 0.0, 2: 0.0}
        self._pinhole_sent: set[int] = set()
        self._berries_key: tuple[Any, ...] | None = None
        plant = rig.plant
        self._centreline = getattr(plant, "centreline", None)  # the Cosserat rod's
        self._arm = ArmDrawer(stream, rr, "world/arm/true", plant.arm.n_sections, 20, offset)
        self._log_static()

    # --- set-up ---------------------------------------------------------------------

    def _log_static(self) -> None:
        rr, rig = self.rr, self.rig
        log_canes(self.stream, rr, rig.bush.branches)
        self.stream.log(
            "world/base", rr.Points3D([[0.0, 0.0, 0.0]], radii=0.01, labels=["base"]), static=True
        )
        vision = rig.vision
        T = vision.T_base_c1
        self.stream.log(
            "world/c1", rr.Transform3D(translation=T[:3, 3], mat3x3=T[:3, :3]), static=True
        )

    def attach(self) -> SimView:
        """Hook onto the rig: the clock's callbacks, the cameras and the detector."""
        rig = self.rig
        rig.clock.on_advance.append(self.tick)
        vision = rig.vision
        vision.frame1 = self._wrap_frame(vision.frame1, 1)
        vision.frame2 = self._wrap_frame(vision.frame2, 2)
        detect = vision.detector.detect
        model1 = vision.model1

        def detect_and_show(image: Any, camera: Any = None) -> Any:
            dets = detect(image, camera)
            which = 1 if camera is model1 else 2
            if self._frames[which] % self.image_every == 0:
                self._detections(which, dets)
            return dets

        vision.detector.detect = detect_and_show  # type: ignore[method-assign]
        self.tick(0.0)
        return self

    # --- per step ---------------------------------------------------------------------

    def tick(self, dt: float = 0.0) -> None:
        """After every simulated time step: the run log's new records, then the truth now."""
        self.drain()
        rr, rig = self.rr, self.rig
        t = rig.clock.now()
        self.stream.set_time(TIMELINE, duration=t)
        plant = rig.plant
        q, pose = plant.q(), plant.pose()
        if self._centreline is not None:  # the rod itself, not arcs
            self._arm.draw(np.asarray(self._centreline()), pose)
        else:
            self._arm.draw_arm(plant.arm, q)
        c2 = pose @ rig.vision.fusion.T_ee_c2
        self.stream.log("world/c2", rr.Transform3D(translation=c2[:3, 3], mat3x3=c2[:3, :3]))
        self._berries()
        gap = rig.watch.clearance.gap(q)
        self.stream.log("errors/true_gap_mm", rr.Scalars(1e3 * float(gap)))
        berry = self._selected()
        if berry is not None:
            grasp = pose[:3, 3] + rig.machine.config.grasp_offset * pose[:3, 2]
            err = float(np.linalg.norm(grasp - berry.position))
            self.stream.log("errors/true_grasp_mm", rr.Scalars(1e3 * err))

    def drain(self) -> None:
        """Log the run-log records written since the last call."""
        records = self.rig.machine.log.records
        for record in records[self._drained :]:
            self.records.log(record)
        self._drained = len(records)

    def close(self) -> None:
        """The last records, then close the recording: the file gets its footer and is
        complete (a spawned viewer keeps what it got)."""
        self.drain()
        close_recording(self.stream, viewer=self.viewer)

    def _selected(self) -> Any:
        tag = self.rig.vision.selected.tag_id
        return next((b for b in self.rig.gripper.on_bush if b.tag_id == tag), None)

    def _berries(self) -> None:
        """The berries on the bush, logged again only when they change (one picked, a new
        one selected)."""
        on_bush = self.rig.gripper.on_bush
        selected = self.rig.vision.selected.tag_id
        key = (selected, *(b.tag_id for b in on_bush))
        if key == self._berries_key:
            return
        self._berries_key = key
        log_berries(self.stream, self.rr, "world/berries", on_bush, selected)

    # --- cameras ----------------------------------------------------------------------

    def _wrap_frame(self, frame: Callable[[float], Any], which: int) -> Callable[[float], Any]:
        def frame_and_show(time: float) -> Any:
            img = frame(time)
            self._frames[which] += 1
            self._frame_time[which] = time
            if img is not None and self._frames[which] % self.image_every == 0:
                self._image(which, time, img)
            return img

        return frame_and_show

    def _image(self, which: int, time: float, img: Any) -> None:
        rr = self.rr
        full = img.full(float(np.median(img[0]))) if hasattr(img, "full") else np.asarray(img)
        path = f"world/c{which}/image"
        self.stream.set_time(TIMELINE, duration=time)
        if which not in self._pinhole_sent:
            model = self.rig.vision.model1 if which == 1 else self.rig.vision.model2
            h, w = full.shape[:2]
            self.stream.log(
                path,
                rr.Pinhole(image_from_camera=model.matrix, resolution=[w, h],
                           image_plane_distance=0.1 if which == 1 else 0.03),
                static=True,
            )  # fmt: skip
            self._pinhole_sent.add(which)
        self.stream.log(path, rr.Image(full).compress(jpeg_quality=self.jpeg_quality))

    def _detections(self, which: int, dets: list[Any]) -> None:
        rr = self.rr
        selected = self.rig.vision.selected.tag_id
        self.stream.set_time(TIMELINE, duration=self._frame_time[which])
        quads = [np.vstack([d.corners, d.corners[:1]]) for d in dets]
        colours = [(255, 0, 255) if d.marker_id == selected else (0, 200, 255) for d in dets]
        self.stream.log(
            f"world/c{which}/image/detections",
            rr.LineStrips2D(
                quads, labels=[f"id {d.marker_id}" for d in dets], colors=colours, radii=1.5
            ),
        )


def attach(
    rig: SimRig,
    record: str | Path | None = None,
    spawn: bool = False,
    image_every: int = 1,
    name: str | None = None,
) -> SimView:
    """A :class:`SimView` of ``rig`` recording to ``record`` (.rrd), a spawned viewer, or
    both; call its ``close()`` after the run."""
    name = name or f"harvest seed {rig.bush.seed}"
    stream = open_recording(name, record, spawn, harvest_blueprint(cameras=True))
    view = SimView(rig, stream, image_every)
    view.viewer = spawn
    return view.attach()
