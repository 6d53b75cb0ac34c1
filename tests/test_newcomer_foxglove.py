"""The Foxglove live view (issue 39, the live view): a test client on 127.0.0.1 speaks
Foxglove's WebSocket protocol to the server, subscribes to every topic, and decodes the
messages it receives (protobuf with the schema the server advertises, or JSON) within a
second of the records being written."""

from __future__ import annotations

import base64
import json
import struct
import time
from typing import Any

import pytest

from softarm.errors import ParameterError

pytest.importorskip("foxglove")
ws_sync = pytest.importorskip("websockets.sync.client")
protobuf = pytest.importorskip("google.protobuf")

from softarm.viz.foxglove_live import LiveView, parse_address  # noqa: E402

STEP = {
    "kind": "step", "t": 1.25, "state": "fine_positioning", "berry": 2,
    "q": [0.01 * k for k in range(9)], "target": [0.02, 0.37, 0.39],
    "pose": [[1, 0, 0, 0.02], [0, 1, 0, 0.36], [0, 0, 1, 0.39], [0, 0, 0, 1]],
    "position_error_m": 4e-4, "orientation_error_rad": 0.01,
}  # fmt: skip
MAP = {"kind": "bush_map", "t": 0.5, "berries": [
    {"id": 0, "position": [0.0, 0.4, 0.4], "radius_m": 0.012, "ripe": True},
    {"id": 1, "position": [0.1, 0.4, 0.4], "radius_m": 0.012, "ripe": False},
], "canes": [{"coeffs": [[0.1, 0.05], [0.4, 0.0], [0.3, 0.2]], "radius_m": 0.004}]}  # fmt: skip
TRANSITION = {"kind": "transition", "t": 1.0, "berry": 2, "old": "initial_placement",
              "new": "fine_positioning", "why": "berry within reach"}  # fmt: skip


def _decoder(channel: dict[str, Any]) -> Any:
    if channel["encoding"] == "json":
        return json.loads
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

    files = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(channel["schema"]))
    pool = descriptor_pool.DescriptorPool()
    for f in files.file:
        pool.Add(f)
    return message_factory.GetMessageClass(
        pool.FindMessageTypeByName(channel["schemaName"])
    ).FromString


class Client:
    """A Foxglove WebSocket client: connects, subscribes to every channel advertised, and
    decodes what it receives by topic."""

    def __init__(self, url: str) -> None:
        self.ws = ws_sync.connect(url, subprotocols=["foxglove.sdk.v1"], open_timeout=5)
        self.ws.__enter__()  # the context manager's start (websockets 15+ wants one)
        self.subscriptions: dict[int, tuple[str, Any]] = {}
        self.got: dict[str, list[Any]] = {}

    def subscribe(self, topics: set[str], deadline_s: float = 5.0) -> None:
        """Read until every one of ``topics`` is advertised, subscribing to each."""
        end = time.monotonic() + deadline_s
        while not topics <= {t for t, _ in self.subscriptions.values()}:
            frame = self.ws.recv(timeout=max(0.01, end - time.monotonic()))
            if isinstance(frame, str) and json.loads(frame)["op"] == "advertise":
                new = json.loads(frame)["channels"]
                for c in new:
                    self.subscriptions[c["id"]] = (c["topic"], _decoder(c))
                subs = [{"id": c["id"], "channelId": c["id"]} for c in new]
                self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))

    def collect(self, topics: set[str], deadline_s: float) -> dict[str, list[Any]]:
        """Messages by topic, until each of ``topics`` has one or ``deadline_s`` passed."""
        end = time.monotonic() + deadline_s
        while time.monotonic() < end and not topics <= set(self.got):
            try:
                frame = self.ws.recv(timeout=max(0.01, end - time.monotonic()))
            except TimeoutError:
                break
            if isinstance(frame, bytes) and frame[0] == 1:  # messageData
                (sub,) = struct.unpack_from("<I", frame, 1)  # then the log time, the data
                topic, decode = self.subscriptions[sub]
                self.got.setdefault(topic, []).append(decode(frame[13:]))
        return self.got

    def close(self) -> None:
        self.ws.close()


TOPICS = {"/joint_states", "/tf", "/bush_map", "/harvest/events", "/harvest/errors"}


def test_a_client_receives_and_decodes_every_topic_within_a_second() -> None:
    records: list[dict[str, Any]] = []
    view = LiveView(records, "127.0.0.1:0")  # this machine only, any free port
    client = Client(view.url)
    try:
        assert view.url.startswith("ws://127.0.0.1:") and view.port > 0
        client.subscribe(TOPICS)
        time.sleep(0.3)  # the server takes the subscription in (the protocol has no ack)
        start = time.monotonic()
        records.extend([MAP, TRANSITION, STEP])  # what the run appends
        got = client.collect(TOPICS, deadline_s=1.0)
        assert TOPICS <= set(got), sorted(got)
        assert time.monotonic() - start < 1.0
        joints = got["/joint_states"][0]
        assert [j.name for j in joints.joints][:2] == ["q0", "q1"]
        assert joints.joints[3].position == pytest.approx(0.03)
        frames = {f.child_frame_id: f for f in got["/tf"][0].transforms}
        assert frames["gripper"].translation.y == pytest.approx(0.36)
        assert frames["target"].translation.z == pytest.approx(0.39)
        spheres = got["/bush_map"][0].entities[0].spheres
        assert len(spheres) == 2 and spheres[0].color.r == 1.0 and spheres[1].color.g > 0.5
        (cane,) = got["/bush_map"][0].entities[1].lines
        assert cane.points[-1].z == pytest.approx(0.5) and len(cane.points) == 40
        assert "fine_positioning" in got["/harvest/events"][0].message
        assert got["/harvest/errors"][0]["position_error_mm"] == pytest.approx(0.4)
    finally:
        client.close()
        view.close()


def test_records_written_with_no_client_are_not_waited_for() -> None:
    records: list[dict[str, Any]] = []
    view = LiveView(records, "127.0.0.1:0")
    try:
        records.extend([STEP] * 2000)  # no client: the run goes on, nothing queues up
        end = time.monotonic() + 20.0
        while view._sent < len(records) and time.monotonic() < end:
            time.sleep(0.05)  # the view's thread reads them, sent to no one
        client = Client(view.url)
        client.subscribe({"/joint_states"})
        time.sleep(0.3)
        records.append({**STEP, "t": 9.0})
        got = client.collect({"/joint_states"}, deadline_s=1.0)
        assert got["/joint_states"][-1].timestamp.seconds == 9
        client.close()
    finally:
        view.close()


@pytest.mark.parametrize(("text", "want"), [("127.0.0.1:9000", ("127.0.0.1", 9000)),
                                            ("8765", ("127.0.0.1", 8765))])  # fmt: skip
def test_addresses(text: str, want: tuple[str, int]) -> None:
    assert parse_address(text) == want


def test_a_bad_address_is_one_line() -> None:
    with pytest.raises(ParameterError, match="HOST:PORT"):
        parse_address("localhost:http")


def test_harvest_serves_the_run_live(tmp_path: Any) -> None:
    import os
    import subprocess
    import sys

    cmd = [sys.executable, "-m", "softarm", "harvest", "--sim", "--berries", "3", "-q",
           "--foxglove", "127.0.0.1:0"]  # fmt: skip
    env = {**os.environ, "MPLBACKEND": "Agg"}
    with subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True, env=env, cwd=tmp_path) as run:
        assert run.stdout is not None
        first = run.stdout.readline()
        assert first.startswith("foxglove: live at ws://127.0.0.1:"), first
        url = first.split()[3]
        client = Client(url)
        topics = {"/joint_states", "/harvest/events", "/c1/image/compressed", "/c1/camera_info"}
        client.subscribe(topics)
        got = client.collect(topics, deadline_s=10.0)
        client.close()
        rest = run.communicate(timeout=300)[0]
    assert topics <= set(got), sorted(got)
    assert len(got["/joint_states"][0].joints) == 9
    assert "harvested" in rest and run.returncode in (0, 1)


def test_without_the_extra_the_line_names_it_before_the_banner(tmp_path: Any) -> None:
    import subprocess
    import sys

    code = ("import sys; sys.modules['foxglove'] = None; from softarm.cli import main; "
            "sys.exit(main(['harvest', '--sim', '--foxglove']))")  # fmt: skip
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)  # fmt: skip
    assert done.returncode == 2 and done.stdout == ""
    assert "pip install 'softarm[foxglove]'" in done.stderr and len(done.stderr.splitlines()) == 1


def test_replay_serves_a_log_at_its_pace_once_a_client_subscribes(tmp_path: Any) -> None:
    import threading

    from softarm.harvest.records.log import HarvestLog
    from softarm.viz.foxglove_live import serve_log

    log = HarvestLog(tmp_path / "run.jsonl")
    for k in range(5):
        log.event("step", **{**{f: v for f, v in STEP.items() if f != "kind"}, "t": 0.1 * k})
    log.close()
    urls: list[str] = []
    served: list[int] = []
    thread = threading.Thread(
        target=lambda: served.append(
            serve_log(tmp_path / "run.jsonl", "127.0.0.1:0", lambda line: urls.append(line))
        )
    )
    thread.start()
    end = time.monotonic() + 10.0
    while not urls and time.monotonic() < end:
        time.sleep(0.02)
    url = urls[0].split(" at ")[1].split(";")[0]
    client = Client(url)
    client.subscribe({"/joint_states"})
    got = client.collect({"/joint_states"}, deadline_s=3.0)
    thread.join(timeout=10.0)
    client.close()
    assert served == [5] and got["/joint_states"], got


def test_the_layout_shows_only_topics_the_view_serves() -> None:
    import re
    from pathlib import Path

    layout = json.loads((Path(__file__).parents[1] / "docs" / "foxglove_layout.json").read_text())
    text = json.dumps(layout["configById"])
    used = set(re.findall(r'"(/[a-z0-9_/]+)', text))
    served = TOPICS | {f"/c{k}/{t}" for k in (1, 2) for t in ("image/compressed", "camera_info")}
    assert used and used <= served, used - served
    panels = set(layout["configById"])
    placed = set(re.findall(r'"([A-Za-z0-9]+![a-z0-9]+)"', json.dumps(layout["layout"])))
    assert placed == panels


def test_tapped_camera_frames_arrive_as_jpeg_with_their_calibration() -> None:
    import types

    import cv2
    import numpy as np

    from softarm.vision import CameraModel

    model = CameraModel.ideal(500.0, 64, 48, [0.01, 0.0, 0.0, 0.0, 0.0])
    image = np.zeros((48, 64, 3), np.uint8)
    image[10:20, 10:30] = (0, 0, 255)
    vision = types.SimpleNamespace(frame1=lambda t: image, model1=model)
    records: list[dict[str, Any]] = []
    view = LiveView(records, "127.0.0.1:0")
    client = Client(view.url)
    try:
        view.attach_cameras(vision)
        topics = {"/c1/image/compressed", "/c1/camera_info"}
        client.subscribe(topics)
        time.sleep(0.3)
        assert vision.frame1(0.5) is image  # the rig gets its frame as before
        got = client.collect(topics, deadline_s=2.0)
        assert topics <= set(got), sorted(got)
        sent = got["/c1/image/compressed"][0]
        assert sent.format == "jpeg" and sent.frame_id == "c1"
        decoded = cv2.imdecode(np.frombuffer(sent.data, np.uint8), cv2.IMREAD_COLOR)
        assert decoded.shape == image.shape and decoded[15, 20, 2] > 200
        info = got["/c1/camera_info"][0]
        assert (info.width, info.height) == (64, 48) and info.K[0] == pytest.approx(500.0)
    finally:
        client.close()
        view.close()
