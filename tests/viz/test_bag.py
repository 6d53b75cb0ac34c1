"""ROS 2 bags (docs/ros.md): a 2-berry simulated harvest written with ``--bag`` and read
back with rosbags: every topic, monotonic stamps, one consistent tf tree whose arm chain
is the model's forward kinematics, and ``replay --bag`` giving the same bag from the log."""

from __future__ import annotations

import json
import sys
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("rosbags")

from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import Reader
from scipy.spatial.transform import Rotation

import softarm
from softarm.cli import main
from softarm.harvest.machine.states import HarvestState
from softarm.harvest.records.log import STEP_RENAMED, read_log
from softarm.units import METRES_PER_PSI
from softarm.viz.bag.convert import TOPICS

NS = 1_000_000_000


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("bag")
    paths = {"log": d / "run.jsonl", "report": d / "report.json", "bag": d / "run.mcap"}
    argv = ["harvest", "--sim", "--berries", "2", "--seed", "3", "-q"]
    for name, path in paths.items():
        argv += [f"--{name}", str(path)]
    assert main(argv) == 0
    return paths


def _read(bag: Path) -> dict[str, list[tuple[int, Any]]]:
    out: dict[str, list[tuple[int, Any]]] = defaultdict(list)
    with AnyReader([bag]) as reader:
        for conn, stamp, raw in reader.messages():
            out[conn.topic].append((stamp, reader.deserialize(raw, conn.msgtype)))
    return dict(out)


@pytest.fixture(scope="module")
def topics(run: dict[str, Path]) -> dict[str, list[tuple[int, Any]]]:
    return _read(run["bag"])


def _ns(stamp: Any) -> int:
    return int(stamp.sec) * NS + int(stamp.nanosec)


def _pose(tf: Any) -> np.ndarray:
    t, r = tf.transform.translation, tf.transform.rotation
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix()
    pose[:3, 3] = [t.x, t.y, t.z]
    return pose


def test_every_topic_with_its_standard_type(run: dict[str, Path]) -> None:
    with AnyReader([run["bag"]]) as reader:
        found = {c.topic: c.msgtype for c in reader.connections}
    assert found == TOPICS


def test_stamps_are_monotonic_and_match_the_headers(
    topics: dict[str, list[tuple[int, Any]]], run: dict[str, Path]
) -> None:
    for topic, items in topics.items():
        stamps = [s for s, _ in items]
        assert stamps == sorted(stamps), topic
        for stamp, msg in items:
            header = getattr(msg, "header", None)
            if header is not None:
                assert _ns(header.stamp) == stamp, topic
    for topic in ("/tf", "/joint_states", "/pressure_command", "/diagnostics"):
        stamps = np.array([s for s, _ in topics[topic]])
        assert np.all(np.diff(stamps) > 0), topic  # one message per control step
    sim_time = json.loads(run["report"].read_text())["sim_time_s"]
    first, last = topics["/tf_static"][0][0], topics["/tf"][-1][0]
    assert (last - first) / NS == pytest.approx(sim_time, abs=0.06)


def _edges(topics: dict[str, list[tuple[int, Any]]]) -> dict[str, str]:
    parents: dict[str, set[str]] = defaultdict(set)
    for topic in ("/tf_static", "/tf"):
        for _, msg in topics[topic]:
            for tf in msg.transforms:
                parents[tf.child_frame_id].add(tf.header.frame_id)
    assert all(len(p) == 1 for p in parents.values()), parents
    return {child: next(iter(p)) for child, p in parents.items()}


def test_the_tf_tree_is_one_tree_rooted_at_the_base(
    topics: dict[str, list[tuple[int, Any]]],
) -> None:
    parent = _edges(topics)
    for frame in parent:
        seen = [frame]
        while seen[-1] in parent:
            seen.append(parent[seen[-1]])
            assert len(seen) < 20, seen  # no cycle
        assert seen[-1] == "base", seen
    expected = {"section_1", "section_2", "section_3", "gripper", "grasp_point", "cube"}
    expected |= {"camera_c1", "camera_c2", "base_tag", "gripper_measured"}
    assert set(parent) == expected
    frames = set(parent) | {"base"}
    for topic in ("/camera_c1/camera_info", "/camera_c2/camera_info", "/harvest/markers"):
        for _, msg in topics[topic][:3]:
            ids = [m.header.frame_id for m in msg.markers] if hasattr(msg, "markers") else []
            assert set(ids or [msg.header.frame_id]) <= frames


def test_the_arm_chain_is_the_model_at_the_joint_states(
    topics: dict[str, list[tuple[int, Any]]], run: dict[str, Path]
) -> None:
    arm = softarm.SoftArm.blackberry()
    steps = {}
    for r in read_log(run["log"]):
        if r["kind"] == "step":
            steps[r["t"]] = r["q"]  # the last step at a time is the one sent
    qs = [np.asarray(m.position) for _, m in topics["/joint_states"]]
    assert len(qs) == len(steps)
    np.testing.assert_allclose(qs, list(steps.values()))
    assert topics["/joint_states"][0][1].name[0] == "section_1_actuator_1"
    for (_, tf), (_, q) in zip(topics["/tf"][::20], topics["/joint_states"][::20], strict=True):
        chain = {t.child_frame_id: _pose(t) for t in tf.transforms}
        ee = chain["section_1"] @ chain["section_2"] @ chain["section_3"]
        # The header keeps the arm to 7 significant digits, as every number of a log.
        np.testing.assert_allclose(ee, arm.forward(q.position), atol=1e-6)
    _, pressures = topics["/pressure_command"][-1]
    np.testing.assert_allclose(pressures.data, qs[-1] / METRES_PER_PSI)
    assert pressures.layout.dim[0].size == 9


def test_cameras_markers_state_and_diagnostics(
    topics: dict[str, list[tuple[int, Any]]],
) -> None:
    _, c1 = topics["/camera_c1/camera_info"][0]
    assert (c1.width, c1.height, c1.distortion_model) == (1280, 720, "plumb_bob")
    assert c1.k[0] == pytest.approx(900.0) and "/camera_c1/image/compressed" not in topics
    names = {m.ns for m in topics["/harvest/markers"][0][1].markers}
    assert {"backbone", "links", "canes", "berries", "estimate", "goal", "plan"} <= names

    def berries(msg: Any) -> int:
        return next(len(m.points) for m in msg.markers if m.ns == "berries")

    assert berries(topics["/harvest/markers"][0][1]) == 2
    assert berries(topics["/harvest/markers"][-1][1]) == 0  # both picked
    states = {m.data for _, m in topics["/harvest/state"]}
    assert states <= {s.value for s in HarvestState} and "done" in states
    status = topics["/diagnostics"][0][1].status[0]
    assert status.name == "softarm_harvest" and status.hardware_id == "sim"
    assert "position_error_mm" in {kv.key for kv in status.values}
    logs = [m.msg for _, m in topics["/rosout"]]
    assert any(text.startswith("berry_result:") for text in logs)


def test_the_bag_reads_as_a_rosbag2_file_without_its_folder(run: dict[str, Path]) -> None:
    """What `ros2 bag info run.mcap` shows, from the MCAP file's own summary."""
    with Reader(run["bag"]) as reader:
        assert reader.message_count == sum(c.msgcount for c in reader.connections)
        # The run's span: from the first record's time to the last one's.
        times = [r["t"] for r in read_log(run["log"]) if isinstance(r.get("t"), float)]
        assert abs(reader.duration / NS - (max(times) - min(times))) < 0.1
        assert {c.topic for c in reader.connections} == set(TOPICS)
        static = next(c for c in reader.connections if c.topic == "/tf_static")
        assert static.ext.offered_qos_profiles[0].durability.name == "TRANSIENT_LOCAL"
    assert b"rosbag2" in run["bag"].read_bytes()[-4096:]  # the metadata record


def test_log_and_report_open_with_the_header(run: dict[str, Path]) -> None:
    header = next(iter(read_log(run["log"])))
    assert header["kind"] == "header" and header["softarm"] == softarm.__version__
    assert header["command"] == "harvest" and header["argv"][:2] == ["harvest", "--sim"]
    assert header["seed"] == 3 and header["options"]["berries"] == 2
    assert len(header["world"]["berries"]) == 2 and header["world"]["canes"]
    assert header["plant"]["model"] == "pcc" and len(header["arm"]["sections"]) == 3
    assert header["units"]["step"]["position_error_m"] == "m"
    assert header["units"]["step"]["orientation_error_rad"] == "rad"
    report = json.loads(run["report"].read_text())
    assert next(iter(report)) == "header" and report["header"] == header


def test_replay_converts_the_log_to_the_same_bag(run: dict[str, Path], tmp_path: Path) -> None:
    out = tmp_path / "replayed.mcap"
    assert main(["replay", str(run["log"]), "--bag", str(out)]) == 0
    live, replayed = _raw(run["bag"]), _raw(out)
    assert live == replayed


def _raw(bag: Path) -> list[tuple[str, int, bytes]]:
    with AnyReader([bag]) as reader:
        return [(c.topic, s, bytes(raw)) for c, s, raw in reader.messages()]


def test_a_log_without_a_header_gets_the_defaults(run: dict[str, Path], tmp_path: Path) -> None:
    old = tmp_path / "old.jsonl"
    old.write_text("".join(run["log"].read_text().splitlines(keepends=True)[1:]))
    out = tmp_path / "old.mcap"
    assert main(["replay", str(old), "--bag", str(out)]) == 0
    topics = _read(out)
    assert set(topics) == set(TOPICS) and topics["/tf_static"][0][0] == 0
    canes = [m for m in topics["/harvest/markers"][0][1].markers if m.ns == "canes"]
    assert canes == []


def test_a_log_from_before_the_unit_names_gives_the_same_bag(
    run: dict[str, Path], tmp_path: Path
) -> None:
    """A format-1 log (a step's ``position_error`` etc. without their units) replays as
    the current log does: read_log renames the fields."""
    renamed = {new: old for old, new in STEP_RENAMED.items()}
    lines = []
    for line in run["log"].read_text().splitlines():
        r = json.loads(line)
        if r["kind"] == "header":
            r["format"] = 1
            r["units"]["step"] = {renamed.get(k, k): v for k, v in r["units"]["step"].items()}
        elif r["kind"] == "step":
            r = {renamed.get(k, k): v for k, v in r.items()}
        lines.append(json.dumps(r) + "\n")
    old = tmp_path / "format1.jsonl"
    old.write_text("".join(lines))
    assert '"position_error":' in old.read_text() and '"position_error_m"' not in old.read_text()
    out = tmp_path / "format1.mcap"
    assert main(["replay", str(old), "--bag", str(out)]) == 0
    assert _raw(out) == _raw(run["bag"])


def test_a_header_of_an_unknown_format_is_refused(
    run: dict[str, Path], tmp_path: Path, capsys
) -> None:
    lines = run["log"].read_text().splitlines(keepends=True)
    header = json.loads(lines[0])
    header["format"] = 3
    log = tmp_path / "future.jsonl"
    log.write_text(json.dumps(header) + "\n" + "".join(lines[1:]))
    assert main(["replay", str(log), "--bag", str(tmp_path / "f.mcap")]) == 2
    err = capsys.readouterr().err.strip()
    assert "header format must be 1 or 2, got 3" in err and "\n" not in err


def test_a_bad_record_names_the_file_and_the_record(tmp_path: Path, capsys) -> None:
    log = tmp_path / "bad.jsonl"
    log.write_text('{"kind": "step", "t": 0.0, "q": [1, 2]}\n{"kind": "step", "t": 0.1}\n')
    assert main(["replay", str(log), "--bag", str(tmp_path / "b.mcap")]) == 2
    err = capsys.readouterr().err.strip()
    assert "bad.jsonl: record 1" in err and "q must be 9 numbers" in err and "\n" not in err
    assert not (tmp_path / "b.mcap").exists()


def test_bag_must_be_an_mcap_file(tmp_path: Path, capsys) -> None:
    log = tmp_path / "run.jsonl"
    argv = ["harvest", "--sim", "--berries", "1", "-q", "--log", str(log)]
    assert main([*argv, "--bag", str(tmp_path / "run.bag")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("softarm harvest: error: --bag must name a .mcap file")
    assert not log.exists()


def test_bag_without_rosbags_fails_before_the_run(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys
) -> None:
    for name in ("rosbags", "rosbags.typesys", "rosbags.rosbag2"):
        monkeypatch.setitem(sys.modules, name, None)
    log, bag = tmp_path / "run.jsonl", tmp_path / "run.mcap"
    argv = ["harvest", "--sim", "--berries", "1", "--log", str(log), "--bag", str(bag)]
    assert main(argv) == 2
    out = capsys.readouterr()
    assert 'pip install "softarm[ros]"' in out.err and "\n" not in out.err.strip()
    assert out.out == "" and not log.exists() and not bag.exists()
    log.write_text('{"kind": "transition", "t": 0.0, "old": "idle", "new": "idle"}\n')
    assert main(["replay", str(log), "--bag", str(bag)]) == 2
    assert 'pip install "softarm[ros]"' in capsys.readouterr().err and not bag.exists()
