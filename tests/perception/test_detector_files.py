"""The files the detector's commands read from users (``softarm detect``, ``softarm
detector evaluate`` and ``train``): every image goes through softarm's one image reader
(bytes to OpenCV, the header's size checked before decoding), so a name that is not
UTF-8 is read instead of crashing OpenCV, a small file that claims a huge image is
refused before it is decoded, and a broken depth or labels file is one line, not a
traceback or an allocation of gigabytes."""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest
from detector_scenes import H, W, disc, draw, write_folder

from softarm.cli import main
from softarm.perception._inputs import MAX_FRAME_PIXELS
from softarm.perception.detector.evaluate import read_depth
from softarm.perception.detector.labels import read_coco


def _png_claiming(width: int, height: int) -> bytes:
    """A PNG whose header says ``width`` x ``height`` grey pixels, with no pixel data."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(kind + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IEND", b"")


def test_detect_reads_a_photo_whose_name_is_not_utf8(tmp_path: Path) -> None:
    # cv2.imread takes the path as a C string and crashes the process on such a name.
    name = os.fsdecode(b"bush\xff.png")
    cv2.imwrite(str(tmp_path / "bush.png"), draw([("ripe", disc(80, 60, 12))]))
    os.rename(tmp_path / "bush.png", tmp_path / name)
    run = subprocess.run(
        [sys.executable, "-m", "softarm", "detect", name, "--detector", "colour"],
        cwd=tmp_path, capture_output=True, timeout=120,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr.decode(errors="replace")
    assert b"1 berries (1 ripe" in run.stdout


def test_detect_refuses_an_image_too_large_before_decoding_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bomb = tmp_path / "bomb.png"
    bomb.write_bytes(_png_claiming(5000, 5000))  # 25 M pixels, over the 16.8 M perception reads
    assert main(["detect", str(bomb)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "IMAGE" in err[0] and "larger than" in err[0]


def test_a_webp_photo_is_read(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    photo = tmp_path / "bush.webp"
    ok, data = cv2.imencode(
        ".webp", draw([("ripe", disc(80, 60, 14))]), [cv2.IMWRITE_WEBP_QUALITY, 101]
    )
    assert ok
    photo.write_bytes(data.tobytes())
    assert main(["detect", str(photo), "--detector", "colour"]) == 0
    assert "1 berries (1 ripe" in capsys.readouterr().out


@pytest.mark.parametrize(
    "content",
    [b"\x93NUMPY garbage", b"", b"not numpy at all"],
    ids=["bad-header", "empty", "text"],
)
def test_a_broken_npy_depth_is_no_depth(tmp_path: Path, content: bytes) -> None:
    (tmp_path / "a.npy").write_bytes(content)
    assert read_depth(tmp_path, tmp_path / "a.png", (H, W)) is None


def test_a_pickled_or_text_npy_depth_is_no_depth(tmp_path: Path) -> None:
    np.save(tmp_path / "a.npy", np.array([[{"x": 1}] * W] * H, dtype=object))
    assert read_depth(tmp_path, tmp_path / "a.png", (H, W)) is None
    np.save(tmp_path / "b.npy", np.full((H, W), "1.0"))
    assert read_depth(tmp_path, tmp_path / "b.png", (H, W)) is None


def test_depth_files_keep_their_units(tmp_path: Path) -> None:
    mm = np.full((H, W), 1250, np.uint16)
    mm[0, 0] = 0  # unknown
    cv2.imwrite(str(tmp_path / "a.png"), mm)
    np.save(tmp_path / "b.npy", np.full((H, W), 0.75, np.float64))
    from_png = read_depth(tmp_path, tmp_path / "a.jpg", (H, W))
    from_npy = read_depth(tmp_path, tmp_path / "b.jpg", (H, W))
    assert from_png is not None and from_npy is not None
    assert np.isnan(from_png[0, 0]) and from_png[1, 1] == np.float32(1.25)
    assert from_npy.dtype == np.float32 and np.all(from_npy == np.float32(0.75))


def test_detect_with_a_broken_depth_file_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    image = tmp_path / "bush.jpg"
    cv2.imwrite(str(image), draw([("ripe", disc(80, 60, 12))]))
    depth = tmp_path / "bush.npy"
    depth.write_bytes(b"\x93NUMPY garbage")
    assert main(["detect", str(image), "--depth", str(depth)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--depth" in err[0]


def _labels_of_size(tmp_path: Path, width: int, height: int) -> Path:
    path = write_folder(tmp_path, [[("ripe", disc(40, 35, 10), True)]])
    coco = json.loads(path.read_text())
    coco["images"][0].update(width=width, height=height)
    path.write_text(json.dumps(coco))
    return path


@pytest.mark.parametrize(
    "size", [(100_000, 100_000), (0, H), (W, -3)], ids=["huge", "zero", "negative"]
)
def test_labels_claiming_an_impossible_size_are_refused(
    tmp_path: Path, size: tuple[int, int]
) -> None:
    # The masks are drawn at the labels' size: a made-up one must not allocate them.
    labels = _labels_of_size(tmp_path, *size)
    with pytest.raises(Exception, match="pixels") as caught:
        read_coco(labels, tmp_path)
    assert type(caught.value).__name__ == "InputError"
    assert str(MAX_FRAME_PIXELS) in str(caught.value)


def test_evaluate_names_an_unreadable_image_and_goes_on(tmp_path: Path) -> None:
    from softarm.perception.detector.choice import detector
    from softarm.perception.detector.evaluate import evaluate

    scenes = [[("ripe", disc(40, 35, 10), True)], [("ripe", disc(80, 60, 10), True)]]
    labels = write_folder(tmp_path, scenes)
    (tmp_path / "images" / "000001.png").write_bytes(_png_claiming(5000, 5000))
    out = tmp_path / "out"
    figures = evaluate(detector("colour"), labels, tmp_path, out=out)
    assert json.loads((out / "metrics.json").read_text())["per_image"] == figures["per_image"]
    good, bad = figures["per_image"]
    assert good == {"image": "000000.png", "detections": 1, "matched": 1}
    assert "000001.png" in bad["error"] and "larger than" in bad["error"]


def test_evaluate_names_an_image_of_another_size_than_its_labels(tmp_path: Path) -> None:
    from softarm.perception.detector.choice import detector
    from softarm.perception.detector.evaluate import evaluate

    labels = write_folder(tmp_path, [[("ripe", disc(40, 35, 10), True)]])
    cv2.imwrite(str(tmp_path / "images" / "000000.png"), np.zeros((H // 2, W, 3), np.uint8))
    (only,) = evaluate(detector("colour"), labels, tmp_path)["per_image"]
    assert only == {
        "image": "000000.png",
        "error": f"is {W} x {H // 2} pixels, its labels say {W} x {H}",
    }
