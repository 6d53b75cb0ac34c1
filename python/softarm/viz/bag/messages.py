"""ROS 2 messages built from numbers: stamps, transforms, joint states, arrays, camera
info, compressed images, log lines and diagnostics, as rosbags' standard message
classes."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ["Messages"]

NS_PER_S = 1_000_000_000


class Messages:
    """Builds messages of one typestore (:func:`softarm.viz.bag.deps.typestore`)."""

    def __init__(self, typestore: Any) -> None:
        self.typestore = typestore
        self.types = typestore.types

    def serialize(self, msg: Any) -> bytes:
        """``msg`` as CDR bytes, as a rosbag2 stores it."""
        return bytes(self.typestore.serialize_cdr(msg, msg.__msgtype__))

    def new(self, msgtype: str, /, **fields: Any) -> Any:
        """A message of type ``pkg/msg/Name``."""
        return self.types[msgtype](**fields)

    def time(self, ns: int) -> Any:
        sec, nanosec = divmod(int(ns), NS_PER_S)
        return self.new("builtin_interfaces/msg/Time", sec=sec, nanosec=nanosec)

    def header(self, ns: int, frame: str) -> Any:
        return self.new("std_msgs/msg/Header", stamp=self.time(ns), frame_id=frame)

    def point(self, xyz: Iterable[float]) -> Any:
        x, y, z = (float(v) for v in xyz)
        return self.new("geometry_msgs/msg/Point", x=x, y=y, z=z)

    def vector(self, xyz: Iterable[float]) -> Any:
        x, y, z = (float(v) for v in xyz)
        return self.new("geometry_msgs/msg/Vector3", x=x, y=y, z=z)

    def quaternion(self, rotation: np.ndarray) -> Any:
        x, y, z, w = Rotation.from_matrix(rotation).as_quat()
        return self.new("geometry_msgs/msg/Quaternion", x=x, y=y, z=z, w=w)

    def pose(self, pose: np.ndarray | None = None) -> Any:
        p = np.eye(4) if pose is None else np.asarray(pose, dtype=np.float64)
        return self.new(
            "geometry_msgs/msg/Pose",
            position=self.point(p[:3, 3]),
            orientation=self.quaternion(p[:3, :3]),
        )

    def color(self, rgba: Sequence[float]) -> Any:
        r, g, b, a = (float(v) for v in rgba)
        return self.new("std_msgs/msg/ColorRGBA", r=r, g=g, b=b, a=a)

    def transform(self, ns: int, parent: str, child: str, pose: np.ndarray) -> Any:
        """``child``'s 4x4 ``pose`` in ``parent`` as a TransformStamped."""
        p = np.asarray(pose, dtype=np.float64)
        tf = self.new(
            "geometry_msgs/msg/Transform",
            translation=self.vector(p[:3, 3]),
            rotation=self.quaternion(p[:3, :3]),
        )
        return self.new(
            "geometry_msgs/msg/TransformStamped",
            header=self.header(ns, parent),
            child_frame_id=child,
            transform=tf,
        )

    def tf(self, transforms: list[Any]) -> Any:
        return self.new("tf2_msgs/msg/TFMessage", transforms=transforms)

    def joint_state(self, ns: int, names: Sequence[str], position: np.ndarray) -> Any:
        empty = np.zeros(0, dtype=np.float64)
        return self.new(
            "sensor_msgs/msg/JointState",
            header=self.header(ns, ""),
            name=list(names),
            position=np.asarray(position, dtype=np.float64),
            velocity=empty,
            effort=empty,
        )

    def float_array(self, values: np.ndarray, label: str) -> Any:
        data = np.asarray(values, dtype=np.float64)
        dim = self.new(
            "std_msgs/msg/MultiArrayDimension", label=label, size=data.size, stride=data.size
        )
        layout = self.new("std_msgs/msg/MultiArrayLayout", dim=[dim], data_offset=0)
        return self.new("std_msgs/msg/Float64MultiArray", layout=layout, data=data)

    def string(self, text: str) -> Any:
        return self.new("std_msgs/msg/String", data=text)

    def camera_info(
        self, ns: int, frame: str, camera: Mapping[str, Any],
        roi: tuple[int, int, int, int] = (0, 0, 0, 0),
    ) -> Any:  # fmt: skip
        """CameraInfo of a header camera (width, height, K, D: the plumb_bob model);
        ``roi`` (x_offset, y_offset, width, height) places a window of the full frame
        (all zero: the full frame)."""
        k = np.asarray(camera["K"], dtype=np.float64).reshape(3, 3)
        p = np.hstack([k, np.zeros((3, 1))])
        x, y, w, h = (int(v) for v in roi)
        roi_msg = self.new(
            "sensor_msgs/msg/RegionOfInterest",
            x_offset=x, y_offset=y, height=h, width=w, do_rectify=False,
        )  # fmt: skip
        return self.new(
            "sensor_msgs/msg/CameraInfo",
            header=self.header(ns, frame),
            height=int(camera["height"]),
            width=int(camera["width"]),
            distortion_model="plumb_bob",
            d=np.asarray(camera["D"], dtype=np.float64).ravel(),
            k=k.ravel(),
            r=np.eye(3).ravel(),
            p=p.ravel(),
            binning_x=0,
            binning_y=0,
            roi=roi_msg,
        )

    def compressed_image(self, ns: int, frame: str, fmt: str, data: bytes) -> Any:
        """A CompressedImage of encoded ``data`` (PNG or JPEG bytes), ``fmt`` as
        compressed_image_transport writes it (``bgr8; png compressed bgr8``)."""
        return self.new(
            "sensor_msgs/msg/CompressedImage",
            header=self.header(ns, frame),
            format=fmt,
            data=np.frombuffer(data, dtype=np.uint8),
        )

    def log(self, ns: int, level: str, name: str, text: str) -> Any:
        """An rcl_interfaces/Log line (for /rosout) at ``level`` (DEBUG ... FATAL)."""
        Log = self.types["rcl_interfaces/msg/Log"]
        return Log(
            stamp=self.time(ns), level=getattr(Log, level), name=name, msg=text,
            file="", function="", line=0,
        )  # fmt: skip

    def diagnostics(
        self, ns: int, name: str, hardware_id: str, level: str, message: str,
        values: Iterable[tuple[str, str]],
    ) -> Any:  # fmt: skip
        """A DiagnosticArray of one status; ``level`` is OK, WARN, ERROR or STALE."""
        Status = self.types["diagnostic_msgs/msg/DiagnosticStatus"]
        status = Status(
            level=getattr(Status, level),
            name=name,
            message=message,
            hardware_id=hardware_id,
            values=[self.new("diagnostic_msgs/msg/KeyValue", key=k, value=v) for k, v in values],
        )
        return self.new(
            "diagnostic_msgs/msg/DiagnosticArray", header=self.header(ns, ""), status=[status]
        )
