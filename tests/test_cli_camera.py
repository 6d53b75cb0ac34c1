"""``softarm camera calibrate`` on rendered ChArUco images: mono, side-by-side stereo
(the ZED2's frames) and two cameras' folders; the files it writes read back as the
cameras and the pair, and each bad argument is one line (exit 2)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from softarm import cli
from softarm.vision import CameraModel

EYE = CameraModel.ideal(900.0, 960, 540, [-0.04, 0.01, 0.0, 0.0, 0.0])
BASELINE = 0.12
BOARD_ARGS = ["--squares", "9", "6", "--square", "0.04", "--marker", "0.03"]


@pytest.fixture(scope="module")
def frames(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder of 10 side-by-side frames (left|right) of a board seen by two cameras
    12 cm apart."""
    from render_required import rendering
    from softarm.sim.render.charuco import BoardSpec, CharucoScene, board_poses

    spec = BoardSpec((9, 6), 0.04, 0.03)
    right = np.eye(4)
    right[0, 3] = BASELINE
    folder = tmp_path_factory.mktemp("zed")
    with rendering():
        scene = CharucoScene(spec, {"left": (EYE, np.eye(4)), "right": (EYE, right)})
        for k, pose in enumerate(board_poses(spec, 10, seed=2, centre=(0.06, 0.0))):
            shot = scene.render(pose)
            cv2.imwrite(str(folder / f"{k:02d}.png"), np.hstack([shot["left"], shot["right"]]))
    scene.close()
    return folder


def _halves(frames: Path, out: Path) -> tuple[Path, Path]:
    """The frames split into a left and a right folder (two OpenCV cameras)."""
    left, right = out / "left", out / "right"
    left.mkdir()
    right.mkdir()
    for f in sorted(frames.glob("*.png")):
        image = cv2.imread(str(f))
        half = image.shape[1] // 2
        cv2.imwrite(str(left / f.name), image[:, :half])
        cv2.imwrite(str(right / f.name), image[:, half:])
    return left, right


def test_mono_writes_opencv_and_ros_files(
    frames: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    left, _ = _halves(frames, tmp_path)
    out = tmp_path / "c2"
    assert cli.main(["camera", "calibrate", str(left), *BOARD_ARGS, "--out", str(out)]) == 0
    assert "rms" in capsys.readouterr().out
    for name in ("camera.yml", "camera.yaml"):
        model = CameraModel.load(out / name)
        assert model.matrix[0, 0] == pytest.approx(900.0, rel=0.005)
        assert model.image_size == (960, 540)


def test_stereo_side_by_side(
    frames: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from softarm.vision.stereo_files import read_stereo

    out = tmp_path / "c1"
    argv = ["camera", "calibrate", str(frames), "--stereo", *BOARD_ARGS, "--out", str(out)]
    assert cli.main(argv) == 0
    assert "baseline" in capsys.readouterr().out
    pair = read_stereo(out / "stereo.yml")
    assert pair.baseline == pytest.approx(BASELINE, abs=1e-3)
    assert pair.left.matrix[0, 0] == pytest.approx(900.0, rel=0.005)
    for name in ("left.yml", "right.yml", "left.yaml", "right.yaml"):
        assert CameraModel.load(out / name).matrix[0, 0] == pytest.approx(900.0, rel=0.005)


def test_stereo_from_two_folders(frames: Path, tmp_path: Path) -> None:
    from softarm.vision.stereo_files import read_stereo

    left, right = _halves(frames, tmp_path)
    out = tmp_path / "c1"
    argv = ["camera", "calibrate", str(left), "--right", str(right), *BOARD_ARGS, "--out", str(out)]
    assert cli.main(argv) == 0
    assert read_stereo(out / "stereo.yml").baseline == pytest.approx(BASELINE, abs=1e-3)


@pytest.mark.parametrize(
    ("make", "extra", "message"),
    [
        (lambda d: None, [], "no image files"),
        (lambda d: (d / "a.png").write_text("not an image"), [], "cannot read"),
        (lambda d: cv2.imwrite(str(d / "a.png"), np.zeros((8, 9, 3), np.uint8)),
         ["--stereo"], "even width"),
        (lambda d: cv2.imwrite(str(d / "a.png"), np.zeros((8, 8, 3), np.uint8)),
         [], "usable views"),
    ],
)  # fmt: skip
def test_bad_input_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], make: object, extra: list[str], message: str
) -> None:
    make(tmp_path)  # type: ignore[operator]
    argv = ["camera", "calibrate", str(tmp_path), *extra, *BOARD_ARGS, "--out", str(tmp_path / "o")]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err


def test_marker_larger_than_square_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cv2.imwrite(str(tmp_path / "a.png"), np.zeros((8, 8, 3), np.uint8))
    argv = ["camera", "calibrate", str(tmp_path), "--right", str(tmp_path), "--squares", "9",
            "6", "--square", "0.03", "--marker", "0.04", "--out", str(tmp_path / "o")]  # fmt: skip
    assert cli.main(argv) == 2
    assert "--marker 0.04 must be smaller than --square 0.03" in capsys.readouterr().err
