"""ROS 2 bags with what perception found and the recorded camera frames (docs/ros.md):
a hand-written log with ``bush_map`` records gives the ``detections`` and
``fitted_canes`` markers; a small frames folder gives CompressedImage topics stamped at
the frames' times. Nothing is rendered: the logs and the images are written here."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

pytest.importorskip("rosbags")


from softarm.cli import main
from softarm.viz.bag.images import IMAGE_TOPICS, image_format, scaled_camera
from softarm.viz.bag.markers import PERCEIVED_ALPHA, RIPE, UNRIPE

from .test_bag import _read

NS = 1_000_000_000
Q = [0.0] * 9


def _step(t: float) -> dict[str, Any]:
    return {"kind": "step", "t": t, "q": Q, "state": "servo"}


def _berry(i: int, ripe: bool, radius: float = 0.01) -> dict[str, Any]:
    return {"id": i, "position": [0.1 * i, 0.3, 0.4], "radius_m": radius, "ripe": ripe,
            "sightings": 2}  # fmt: skip


CANE = {"coeffs": [[0.0, 0.1, 0.0, 0.0], [0.3, 0.0, 0.0, 0.0], [0.0, 0.6, 0.0, 0.0]],
        "radius_m": 0.006}  # fmt: skip


def _log(path: Path, records: list[dict[str, Any]]) -> Path:
    path.write_text("".join(json.dumps(r) + "\n" for r in records))
    return path


def _ns(stamp: Any) -> int:
    return int(stamp.sec) * NS + int(stamp.nanosec)


def _perceived(msg: Any) -> dict[tuple[str, int], Any]:
    return {(m.ns, m.id): m for m in msg.markers if m.ns in ("detections", "fitted_canes")}


def test_the_markers_draw_the_latest_bush_map(tmp_path: Path) -> None:
    log = _log(tmp_path / "run.jsonl", [
        _step(0.0),
        {"kind": "bush_map", "t": 0.05, "berries": [_berry(1, True), _berry(2, False, 0.008)],
         "canes": [CANE]},
        _step(0.1),
        {"kind": "bush_map", "t": 0.2, "berries": [_berry(2, True, 0.008)], "canes": []},
        _step(0.2),
        _step(0.3),
    ])  # fmt: skip
    bag = tmp_path / "run.mcap"
    assert main(["replay", str(log), "--bag", str(bag)]) == 0
    markers = _read(bag)["/harvest/markers"]
    by_time: dict[int, Any] = {}
    for stamp, msg in markers:
        by_time[stamp] = msg  # the step's, after the map's at the same time
    assert _perceived(by_time[0]) == {}  # before the first map
    first = _perceived(by_time[round(0.1 * NS)])
    assert set(first) == {("detections", 1), ("detections", 2), ("fitted_canes", 0)}
    ripe, unripe = first["detections", 1], first["detections", 2]
    assert ripe.type == ripe.SPHERE and ripe.action == ripe.ADD
    assert ripe.scale.x == pytest.approx(0.02) and unripe.scale.x == pytest.approx(0.016)
    assert ripe.pose.position.x == pytest.approx(0.1) and ripe.pose.position.z == 0.4
    rgba = lambda c: [c.r, c.g, c.b, c.a]  # noqa: E731
    np.testing.assert_allclose(rgba(ripe.color), [*RIPE[:3], PERCEIVED_ALPHA])
    np.testing.assert_allclose(rgba(unripe.color), [*UNRIPE[:3], PERCEIVED_ALPHA])
    cane = first["fitted_canes", 0]
    assert cane.type == cane.LINE_STRIP and cane.scale.x == pytest.approx(0.012)
    ends = [[p.x, p.y, p.z] for p in (cane.points[0], cane.points[-1])]
    np.testing.assert_allclose(ends, [[0.0, 0.3, 0.0], [0.1, 0.3, 0.6]])
    # The map at t = 0.05 s is drawn at once, and by the next step.
    assert set(_perceived(by_time[round(0.05 * NS)])) == set(first)
    # The second map drops berry 1 and the cane: the viewer is told to delete them.
    second = _perceived(by_time[round(0.3 * NS)])
    assert second["detections", 1].action == second["detections", 1].DELETE
    assert second["fitted_canes", 0].action == second["fitted_canes", 0].DELETE
    assert second["detections", 2].action == second["detections", 2].ADD
    np.testing.assert_allclose(rgba(second["detections", 2].color)[:3], RIPE[:3])
    lines = [m.msg for _, m in _read(bag)["/rosout"]]
    assert "bush_map: 2 berries (1 ripe), 1 canes" in lines


def test_a_bad_bush_map_names_the_record(tmp_path: Path, capsys) -> None:
    bad = {"kind": "bush_map", "t": 0.1, "berries": [_berry(1, True, -0.01)], "canes": []}
    log = _log(tmp_path / "bad.jsonl", [_step(0.0), bad])
    assert main(["replay", str(log), "--bag", str(tmp_path / "b.mcap")]) == 2
    err = capsys.readouterr().err.strip()
    assert "record 2" in err and "radius_m must be a positive number" in err
    assert "\n" not in err and not (tmp_path / "b.mcap").exists()


def _png(image: np.ndarray) -> bytes:
    ok, data = cv2.imencode(".png", image)
    assert ok
    return bytes(data)


def _frames(folder: Path, missing: bool = False) -> dict[str, bytes]:
    """A frames folder as ``--record-frames`` writes it: two C2 frames (the second a
    JPEG), C1's left eye at a look and one grey 4 x 4 window of it."""
    folder.mkdir()
    rng = np.random.default_rng(0)
    _, jpeg = cv2.imencode(".jpg", rng.integers(0, 255, (24, 32, 3), dtype=np.uint8))
    files = {
        "c2_000000.png": _png(rng.integers(0, 255, (24, 32, 3), dtype=np.uint8)),
        "c2_000001.jpg": bytes(jpeg),
        "c1_left_000000.png": _png(rng.integers(0, 255, (9, 16, 3), dtype=np.uint8)),
        "c1_000000.png": _png(rng.integers(0, 255, (4, 4), dtype=np.uint8)),
    }
    for name, data in files.items():
        if not (missing and name == "c2_000001.jpg"):
            (folder / name).write_bytes(data)
    entries = [
        {"camera": "c2", "n": 0, "t": 0.0, "file": "c2_000000.png"},
        {"camera": "c1_left", "n": 0, "t": 0.05, "file": "c1_left_000000.png"},
        {"camera": "c1_right", "n": 0, "t": 0.05, "file": None},
        {"camera": "c2", "n": 1, "t": 0.1, "file": "c2_000001.jpg"},
        {"camera": "c1", "n": 0, "t": 0.1, "file": "c1_000000.png", "origin": [5, 3],
         "full_size": [16, 9]},
        {"camera": "c2", "n": 2, "t": 0.2, "file": None},  # no image then
    ]  # fmt: skip
    (folder / "frames.json").write_text(json.dumps({"frames": entries, "streams": {}}))
    return files


def test_recorded_frames_become_compressed_images(tmp_path: Path, capsys) -> None:
    files = _frames(tmp_path / "frames")
    log = _log(tmp_path / "run.jsonl", [_step(0.0), _step(0.1), _step(0.2)])
    bag = tmp_path / "run.mcap"
    argv = ["replay", str(log), "--bag", str(bag), "--frames", str(tmp_path / "frames")]
    assert main(argv) == 0
    assert "4 images" in capsys.readouterr().out
    topics = _read(bag)
    assert set(IMAGE_TOPICS) <= set(topics)
    c2 = topics["/camera_c2/image/compressed"]
    assert [s for s, _ in c2] == [0, round(0.1 * NS)]
    assert [m.format for _, m in c2] == ["bgr8; png compressed bgr8", "bgr8; jpeg compressed bgr8"]
    assert bytes(c2[0][1].data) == files["c2_000000.png"]
    assert bytes(c2[1][1].data) == files["c2_000001.jpg"]
    (stamp, c1), = topics["/camera_c1/image/compressed"]  # fmt: skip
    assert stamp == round(0.05 * NS) and c1.header.frame_id == "camera_c1"
    assert bytes(c1.data) == files["c1_left_000000.png"]
    (stamp, window), = topics["/camera_c1/window/image/compressed"]  # fmt: skip
    (info_stamp, info), = topics["/camera_c1/window/camera_info"]  # fmt: skip
    assert stamp == info_stamp == round(0.1 * NS) and window.format == "mono8; png compressed"
    roi = info.roi
    assert (roi.x_offset, roi.y_offset, roi.width, roi.height) == (5, 3, 4, 4)
    assert (info.width, info.height) == (16, 9) and info.header.frame_id == "camera_c1"
    for topic, items in topics.items():
        for s, msg in items:
            if hasattr(msg, "header"):
                assert _ns(msg.header.stamp) == s, topic
    # The cameras' CameraInfo is that of the frames: the nominal 640 x 480 C2 at 32 x 24.
    _, c2_info = topics["/camera_c2/camera_info"][0]
    assert (c2_info.width, c2_info.height) == (32, 24)
    np.testing.assert_allclose(c2_info.k, [15.0, 0, 15.5, 0, 15.0, 11.5, 0, 0, 1])


def test_without_frames_no_image_topics(tmp_path: Path) -> None:
    log = _log(tmp_path / "run.jsonl", [_step(0.0), _step(0.1)])
    bag = tmp_path / "run.mcap"
    assert main(["replay", str(log), "--bag", str(bag)]) == 0
    topics = _read(bag)
    assert not set(IMAGE_TOPICS) & set(topics)
    assert (topics["/camera_c2/camera_info"][0][1].width) == 640


def test_a_missing_frame_file_is_a_one_line_error(tmp_path: Path, capsys) -> None:
    _frames(tmp_path / "frames", missing=True)
    log = _log(tmp_path / "run.jsonl", [_step(0.0)])
    bag = tmp_path / "run.mcap"
    argv = ["replay", str(log), "--bag", str(bag), "--frames", str(tmp_path / "frames")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "c2_000001.jpg" in err and "is missing" in err and "\n" not in err
    assert not bag.exists()


def test_frames_need_a_bag(tmp_path: Path, capsys) -> None:
    log = _log(tmp_path / "run.jsonl", [_step(0.0)])
    assert main(["replay", str(log), "--frames", str(tmp_path)]) == 2
    assert "--frames" in capsys.readouterr().err


def test_image_format_and_scaled_camera() -> None:
    grey16 = np.zeros((2, 2), dtype=np.uint16)
    assert image_format(grey16, _png(grey16)) == "mono16; png compressed"
    bgra = np.zeros((2, 2, 4), dtype=np.uint8)
    assert image_format(bgra, _png(bgra)) == "bgra8; png compressed bgra8"
    camera = {"width": 640, "height": 480, "K": np.diag([300.0, 300.0, 1.0]), "D": [0.0]}
    camera["K"][:2, 2] = 319.5, 239.5
    half = scaled_camera(camera, 320, 240)
    np.testing.assert_allclose(half["K"], [[150, 0, 159.5], [0, 150, 119.5], [0, 0, 1]])
    assert scaled_camera(camera, 640, 480)["K"] is camera["K"]


def test_a_frame_file_that_is_not_an_image_is_a_one_line_error(tmp_path: Path, capsys) -> None:
    _frames(tmp_path / "frames")
    (tmp_path / "frames" / "c2_000001.jpg").write_bytes(b"not an image")
    log = _log(tmp_path / "run.jsonl", [_step(0.0)])
    bag = tmp_path / "run.mcap"
    bag.write_bytes(b"an older bag")
    argv = ["replay", str(log), "--bag", str(bag), "--frames", str(tmp_path / "frames")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "c2_000001.jpg" in err and "is not a PNG or JPEG image" in err and "\n" not in err
    assert bag.read_bytes() == b"an older bag"
