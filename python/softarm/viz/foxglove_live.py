"""A live view of a harvest in Foxglove (``softarm harvest --foxglove [HOST:PORT]``): a
WebSocket server of Foxglove's own SDK (the ``foxglove`` extra, ``foxglove-sdk``) that
streams the run log's records as they are written, for Foxglove's desktop or web app
(Open connection, Foxglove WebSocket, ``ws://HOST:PORT``; docs/ros.md).

Topics (Foxglove's schemas, protobuf; times are the run's own clock):

* ``/joint_states`` (``foxglove.JointStates``): the nine elongations ``q0``..``q8`` (m);
* ``/tf`` (``foxglove.FrameTransforms``): ``base`` to ``gripper`` (the gripper as the
  cameras measured it) and ``base`` to ``target`` (the berry being picked);
* ``/bush_map`` (``foxglove.SceneUpdate``): the map's berries, ripe magenta, unripe
  green, and its fitted canes, amber;
* ``/harvest/events`` (``foxglove.Log``): the state machine's transitions, faults, vents,
  plans, each as one line;
* ``/harvest/errors`` (JSON): the measured position and pointing errors of each step;
* ``/c1/image/compressed``, ``/c2/image/compressed`` (``foxglove.CompressedImage``, JPEG)
  with ``/c1/camera_info``, ``/c2/camera_info`` (``foxglove.CameraCalibration``): the
  cameras' frames as the rig's vision took them, where :meth:`LiveView.attach_cameras`
  tapped them (the simulated rigs' ``frame1``/``frame2``).

The control loop only appends records to the log (and a tapped frame to a short queue
that drops the oldest); a thread here reads them, encodes the frames and hands all to
the SDK, which keeps a bounded queue per client and drops the oldest data for one that
is slow: a client never blocks the loop.
"""

from __future__ import annotations

import importlib
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from softarm.errors import MissingDependencyError, ParameterError
from softarm.so3 import quaternion_xyzw

__all__ = ["LiveView", "parse_address", "require_foxglove", "serve_log"]

#: Where the server listens unless told: this machine only.
DEFAULT_ADDRESS = "127.0.0.1:8765"
#: Camera frames kept for the view's thread; older ones are dropped, never waited for.
FRAMES_KEPT = 4
#: Most frames sent per second of wall time, per camera: a simulated run takes frames
#: far faster than a camera does, and each costs a JPEG encoding.
IMAGE_HZ = 5.0
#: JPEG quality of the frames sent.
JPEG_QUALITY = 80
#: How often (s) the publishing thread reads the new records.
POLL_S = 0.02
#: Messages kept per client before the oldest are dropped (the SDK's backlog).
BACKLOG = 1024
#: Record kinds sent to /harvest/events, and their Foxglove log level.
EVENT_LEVELS = {"transition": "Info", "plan": "Info", "survey_done": "Info", "vent": "Warning",
                "fault": "Error", "crash": "Fatal", "interrupted": "Warning",
                "berry_result": "Info"}  # fmt: skip


def require_foxglove() -> Any:
    """The ``foxglove`` module (foxglove-sdk), or :class:`MissingDependencyError`."""
    try:
        return importlib.import_module("foxglove")
    except ImportError as exc:
        raise MissingDependencyError(
            f"the Foxglove live view needs foxglove-sdk: pip install 'softarm[foxglove]' ({exc})",
            "foxglove",
        ) from exc


def parse_address(text: str) -> tuple[str, int]:
    """``HOST:PORT`` (or ``PORT``, on 127.0.0.1) as (host, port); port 0: any free one."""
    host, _, port = text.rpartition(":")
    try:
        number = int(port)
    except ValueError:
        raise ParameterError(f"--foxglove: give HOST:PORT, got {text!r}") from None
    if not 0 <= number <= 65535:
        raise ParameterError(f"--foxglove: port must be in [0, 65535], got {number}")
    return host or "127.0.0.1", number


class LiveView:
    """Serves ``records`` (a run log's list, appended to by the run) on ``address`` from
    a daemon thread until :meth:`close`; :attr:`port` is the port bound."""

    def __init__(
        self, records: list[dict[str, Any]], address: str = DEFAULT_ADDRESS, listener: Any = None
    ) -> None:
        fox = require_foxglove()
        host, port = parse_address(address)
        from foxglove import channels

        self._fox, self.records = fox, records
        self._m = importlib.import_module("foxglove.messages")
        self.context = fox.Context()
        try:
            self.server = fox.start_server(
                name="softarm harvest", host=host, port=port, context=self.context,
                message_backlog_size=BACKLOG, server_listener=listener,
            )  # fmt: skip
        except Exception as exc:  # the SDK's own error type: a port in use, a bad host
            raise ParameterError(f"--foxglove {address}: cannot listen there ({exc})") from None
        self.port: int = self.server.port
        self.host = host
        ctx = self.context
        self._joints = channels.JointStatesChannel("/joint_states", context=ctx)
        self._tf = channels.FrameTransformsChannel("/tf", context=ctx)
        self._map = channels.SceneUpdateChannel("/bush_map", context=ctx)
        self._events = channels.LogChannel("/harvest/events", context=ctx)
        self._errors = fox.Channel("/harvest/errors", message_encoding="json", context=ctx)
        self._image_channels = {
            k: (
                channels.CompressedImageChannel(f"/c{k}/image/compressed", context=ctx),
                channels.CameraCalibrationChannel(f"/c{k}/camera_info", context=ctx),
            )
            for k in (1, 2)
        }
        #: Frames handed over by the tapped cameras: (camera, t, image, model).
        self._images: deque[tuple[int, float, Any, Any]] = deque(maxlen=FRAMES_KEPT)
        self._sent = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="foxglove", daemon=True)
        self._thread.start()

    @property
    def url(self) -> str:
        """The address a Foxglove app connects to."""
        return f"ws://{self.host}:{self.port}"

    def close(self) -> None:
        """Send what is left, then stop the server."""
        self._stop.set()
        self._thread.join(timeout=5.0)
        self._drain()
        self.server.stop()

    def attach_cameras(self, vision: Any) -> None:
        """Tap ``vision``'s camera frames (``frame1``/``frame2`` with their ``model1``/
        ``model2``, where it has them): each frame is handed over as it is, and this
        view's thread encodes and sends it with its calibration."""
        for k in (1, 2):
            frame, model = getattr(vision, f"frame{k}", None), getattr(vision, f"model{k}", None)
            if callable(frame) and model is not None:
                setattr(vision, f"frame{k}", self._tap(frame, k, model))

    def _tap(self, frame: Callable[..., Any], k: int, model: Any) -> Callable[..., Any]:
        last = [-np.inf]  # wall time of the last frame handed over

        def tapped(t: float, *args: Any, **kwargs: Any) -> Any:
            image = frame(t, *args, **kwargs)
            now = time.monotonic()
            if image is not None and now - last[0] >= 1.0 / IMAGE_HZ:
                last[0] = now
                self._images.append((k, float(t), image, model))
            return image

        return tapped

    def _run(self) -> None:
        while not self._stop.wait(POLL_S):
            self._drain()

    def _drain(self) -> None:
        while self._sent < len(self.records):
            record = self.records[self._sent]
            try:
                self.publish(record)
            except Exception:  # a record the view cannot draw must not end the run
                pass
            self._sent += 1
        while self._images:
            k, t, image, model = self._images.popleft()
            try:
                self._image(k, t, image, model)
            except Exception:  # a frame the view cannot encode must not end the run
                pass

    def publish(self, record: dict[str, Any]) -> None:
        """One run-log record on its topics (most kinds have none)."""
        m = self._m
        kind, t = record.get("kind"), float(record.get("t") or 0.0)
        stamp = m.Timestamp(sec=int(t), nsec=round((t - int(t)) * 1e9) % 1_000_000_000)
        if kind == "step":
            self._step(record, stamp)
        elif kind == "bush_map":
            self._map.log(_scene(m, record, stamp))
        if kind in EVENT_LEVELS:
            text = ", ".join(f"{k}={v}" for k, v in record.items() if k not in ("kind", "t"))
            level = getattr(m.LogLevel, EVENT_LEVELS[kind])
            self._events.log(m.Log(timestamp=stamp, level=level, name=kind, message=text[:500]))

    def _image(self, k: int, t: float, image: Any, model: Any) -> None:
        """Camera ``k``'s frame as JPEG, and its calibration, on its two topics."""
        import cv2

        m = self._m
        ok, jpeg = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
        if not ok:
            return
        stamp = m.Timestamp(sec=int(t), nsec=round((t - int(t)) * 1e9) % 1_000_000_000)
        frame_id = f"c{k}"
        images, infos = self._image_channels[k]
        images.log(m.CompressedImage(timestamp=stamp, frame_id=frame_id, data=jpeg.tobytes(),
                                     format="jpeg"))  # fmt: skip
        K = np.asarray(model.matrix, float)
        P = np.hstack([K, np.zeros((3, 1))])
        infos.log(m.CameraCalibration(
            timestamp=stamp, frame_id=frame_id, width=int(image.shape[1]),
            height=int(image.shape[0]), distortion_model="plumb_bob",
            D=[float(v) for v in np.ravel(model.distortion)[:5]], K=K.ravel().tolist(),
            R=np.eye(3).ravel().tolist(), P=P.ravel().tolist(),
        ))  # fmt: skip

    def _step(self, record: dict[str, Any], stamp: Any) -> None:
        m = self._m
        q = record.get("q") or []
        joints = [m.JointState(name=f"q{k}", position=float(v)) for k, v in enumerate(q)]
        self._joints.log(m.JointStates(timestamp=stamp, joints=joints))
        frames = []
        if record.get("pose") is not None:
            frames.append(_transform(m, stamp, "gripper", np.asarray(record["pose"], float)))
        if record.get("target") is not None:
            target = np.asarray(record["target"], float)
            if target.shape == (3,):
                pose = np.eye(4)
                pose[:3, 3] = target
                target = pose
            frames.append(_transform(m, stamp, "target", target.reshape(4, 4)))
        if frames:
            self._tf.log(m.FrameTransforms(transforms=frames))
        if record.get("position_error_m") is not None:
            self._errors.log({
                "t": record.get("t"), "state": record.get("state"), "berry": record.get("berry"),
                "position_error_mm": 1e3 * float(record["position_error_m"]),
                "orientation_error_deg": float(np.degrees(record["orientation_error_rad"] or 0.0)),
            })  # fmt: skip


def _transform(m: Any, stamp: Any, child: str, pose: np.ndarray) -> Any:
    x, y, z, w = quaternion_xyzw(pose[:3, :3])
    return m.FrameTransform(
        timestamp=stamp, parent_frame_id="base", child_frame_id=child,
        translation=m.Vector3(x=pose[0, 3], y=pose[1, 3], z=pose[2, 3]),
        rotation=m.Quaternion(x=x, y=y, z=z, w=w),
    )  # fmt: skip


def _scene(m: Any, record: dict[str, Any], stamp: Any) -> Any:
    """The map's berries as spheres of their size, ripe magenta, unripe green."""
    spheres = []
    for b in record.get("berries", []):
        x, y, z = (float(v) for v in b["position"])
        d = 2.0 * float(b.get("radius_m") or 0.01)
        colour = m.Color(r=1.0, g=0.0, b=1.0, a=0.9) if b.get("ripe") else m.Color(
            r=0.0, g=0.85, b=0.0, a=0.9)  # fmt: skip
        spheres.append(m.SpherePrimitive(
            pose=m.Pose(position=m.Vector3(x=x, y=y, z=z), orientation=m.Quaternion(w=1.0)),
            size=m.Vector3(x=d, y=d, z=d), color=colour,
        ))  # fmt: skip
    canes = [_cane(m, c) for c in record.get("canes", [])]
    berries = m.SceneEntity(timestamp=stamp, frame_id="base", id="berries", spheres=spheres)
    fitted = m.SceneEntity(timestamp=stamp, frame_id="base", id="canes", lines=canes)
    return m.SceneUpdate(entities=[berries, fitted])


def _cane(m: Any, cane: dict[str, Any]) -> Any:
    """A fitted cane (its polynomial's coefficients, (3, degree + 1), over u in [0, 1])
    as an amber line of its thickness."""
    coeffs = np.asarray(cane["coeffs"], float)
    u = np.linspace(0.0, 1.0, 40)
    points = coeffs @ np.vander(u, coeffs.shape[1], increasing=True).T
    return m.LinePrimitive(
        type=m.LinePrimitiveLineType.LineStrip,
        thickness=2.0 * float(cane.get("radius_m") or 0.004), scale_invariant=False,
        points=[m.Point3(x=x, y=y, z=z) for x, y, z in points.T],
        color=m.Color(r=1.0, g=0.78, b=0.0, a=1.0),
    )  # fmt: skip


class _Subscribed:
    """A server listener that notes the first subscription of any client."""

    def __init__(self) -> None:
        self.event = threading.Event()

    def on_subscribe(self, client: Any, channel: Any) -> None:
        self.event.set()

    def on_unsubscribe(self, client: Any, channel: Any) -> None:
        return None


def serve_log(path: str | Path, address: str, announce: Callable[[str], None] = print) -> int:
    """``softarm replay LOG --foxglove``: serve the run log at ``path`` at the run's own
    pace (its records' ``t``), from the moment a Foxglove client subscribes; the number
    of records served."""
    from softarm.harvest.records.log import read_log

    records: list[dict[str, Any]] = []
    listener = _Subscribed()
    view = LiveView(records, address, listener)
    try:
        announce(f"foxglove: serving {path} at {view.url}; waiting for a client to subscribe")
        listener.event.wait()
        start, first = time.monotonic(), None
        for record in read_log(path):
            t = record.get("t")
            if isinstance(t, int | float):
                first = t if first is None else first
                time.sleep(max(0.0, (t - first) - (time.monotonic() - start)))
            records.append(record)
    finally:
        view.close()
    return len(records)
