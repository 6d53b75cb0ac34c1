"""A harvest run as a ROS 2 bag (rosbag2 in one MCAP file), without a ROS install: the
records of a run log (:mod:`softarm.harvest.records.log`) become standard ROS 2 messages, written
with the pure-Python ``rosbags`` package (the ``ros`` extra). See docs/ros.md for the
topics and frames.

One file per job: :mod:`~softarm.viz.bag.deps` (the optional dependency),
:mod:`~softarm.viz.bag.messages` (message builders), :mod:`~softarm.viz.bag.markers`
(the scene as markers), :mod:`~softarm.viz.bag.scene` (what the header describes),
:mod:`~softarm.viz.bag.convert` (records to messages),
:mod:`~softarm.viz.bag.images` (recorded camera frames to images) and
:mod:`~softarm.viz.bag.writer` (the MCAP file).
"""

from softarm.viz.bag.deps import INSTALL, require_rosbags
from softarm.viz.bag.writer import BagSummary, check_bag_path, write_bag

__all__ = ["INSTALL", "BagSummary", "check_bag_path", "require_rosbags", "write_bag"]
