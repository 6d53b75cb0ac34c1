"""A run log written as a rosbag2 bag in one MCAP file (rosbags: no ROS install needed).

rosbags writes a bag directory (``metadata.yaml`` and ``<name>.mcap``); the MCAP file
also carries that metadata in its own ``rosbag2`` record, as ROS 2 writes it, so the
single file is the bag: Foxglove opens it and ``ros2 bag info run.mcap`` reads it. It
is written beside the target and renamed over it once complete. With a frames folder
(:mod:`~softarm.viz.bag.images`) the recorded camera frames go in too, merged with the
log's messages in the order of their stamps.
"""

from __future__ import annotations

import heapq
import tempfile
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from softarm.errors import InputError, OutputError
from softarm.files import atomic_path, check_target
from softarm.harvest.records.header import split_runs
from softarm.viz.bag.convert import TOPICS, Converter
from softarm.viz.bag.deps import require_rosbags, typestore
from softarm.viz.bag.images import IMAGE_TOPICS, FrameImages
from softarm.viz.bag.messages import Messages

__all__ = ["BagSummary", "check_bag_path", "write_bag"]

ALL_TOPICS = {**TOPICS, **IMAGE_TOPICS}
#: rosbag2's metadata version (9: Jazzy and later; the MCAP readers of older releases
#: read the file through its own summary).
VERSION = 9


@dataclass(frozen=True)
class BagSummary:
    """What a bag holds: messages per topic, and its first and last stamps (ns)."""

    path: Path
    counts: dict[str, int]
    start_ns: int
    end_ns: int

    @property
    def messages(self) -> int:
        return sum(self.counts.values())


def check_bag_path(path: str | Path) -> Path:
    """``path`` checked before a run: a ``.mcap`` file name (not a folder), and the
    rosbags package installed (:class:`MissingDependencyError` names the ``ros`` extra)."""
    p = Path(path)
    if p.suffix != ".mcap":
        raise InputError(f"--bag must name a .mcap file, got {str(path)!r}")
    require_rosbags()
    check_target(p, "bag")
    return p


def write_bag(
    records: Iterable[Any], path: str | Path, frames: str | Path | None = None
) -> BagSummary:
    """Write the messages of ``records`` (a run log's, header first) to the MCAP bag
    ``path``, with the camera frames recorded in the folder ``frames`` (``--record-frames``)
    when given; an existing file is replaced only once the new one is complete.

    Raises:
        InputError: a record is malformed (the message names its number and field), or
            the records hold more than one run (a log appended to: pick one with
            :func:`softarm.harvest.records.header.split_runs`).
        ConfigError: the frames folder is broken: no index, a frame file missing or not
            an image (the file named).
        MissingDependencyError: rosbags (the ``ros`` extra) is not installed.
        OutputError: the file cannot be written.
    """
    target = check_bag_path(path)
    rosbag2 = require_rosbags()
    m = Messages(typestore())
    recs = list(records)
    runs = len(split_runs(recs))
    if runs > 1:  # the second run's clock restarts at 0: its steps would collapse
        raise InputError(f"the records hold {runs} runs (header records); a bag holds one")
    converter = Converter.for_records(m, recs)
    # The folder is checked before any writing; the cameras are as the frames were taken.
    images = None if frames is None else FrameImages(m, frames, converter.scene)
    if images is not None:
        converter.scene = images.scene
    messages: Iterator[Any] = converter.messages(recs)
    if images is not None:
        messages = heapq.merge(messages, images.messages(), key=lambda item: item.ns)
    with (
        atomic_path(target, "bag") as tmp,
        tempfile.TemporaryDirectory(prefix=".bag-", dir=target.parent) as folder,
    ):
        bag = Path(folder) / target.stem
        writer = rosbag2.Writer(bag, version=VERSION, storage_plugin=rosbag2.StoragePlugin.MCAP)
        counts = _write(writer, m, messages)
        mcap = next(bag.glob("*.mcap"), None)
        if mcap is None:
            raise OutputError(f"cannot write bag {str(path)!r}: rosbags wrote no .mcap file")
        mcap.replace(tmp)
    return BagSummary(target, *counts)


def _write(writer: Any, m: Messages, messages: Iterable[Any]) -> tuple[dict[str, int], int, int]:
    """Write every message, adding each topic's connection on its first message."""
    connections: dict[str, Any] = {}
    counts: dict[str, int] = {}
    first, last = 2**63 - 1, 0
    with writer:
        for item in messages:
            if item.topic not in connections:
                connections[item.topic] = writer.add_connection(
                    item.topic, ALL_TOPICS[item.topic], typestore=m.typestore,
                    offered_qos_profiles=_qos(item.topic),
                )  # fmt: skip
            writer.write(connections[item.topic], item.ns, m.serialize(item.msg))
            counts[item.topic] = counts.get(item.topic, 0) + 1
            first, last = min(first, item.ns), max(last, item.ns)
    return counts, first, last


def _qos(topic: str) -> list[Any]:
    """/tf_static is latched (transient local), as tf2's static broadcaster offers it."""
    if topic != "/tf_static":
        return []
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    never = QosTime(0, 0)
    return [
        Qos(
            QosHistory.KEEP_LAST, 1, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL,
            never, never, QosLiveliness.AUTOMATIC, never, False,
        )
    ]  # fmt: skip
