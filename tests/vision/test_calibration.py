import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm.errors import VisionError
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import TexturedPlane
from softarm.vision import CameraModel, calibrate_charuco, calibrate_chessboard
from softarm.vision.dictionaries import get_dictionary

TRUTH = CameraModel.ideal(900.0, 1280, 720, [-0.08, 0.03, 0.0, 0.0, 0.0])


def _views(texture: np.ndarray, width: float, height: float, n: int = 10) -> list[np.ndarray]:
    """``n`` tilted views of a planar target filling a good part of the frame."""
    cam = SyntheticCamera(TRUTH, 1280, 720, noise_std=1.0, seed=3)
    rng = np.random.default_rng(4)
    images = []
    for _ in range(n):
        pose = np.eye(4)
        tilt = Rotation.from_rotvec(rng.uniform(-0.5, 0.5, 3) * [1, 1, 0.3])
        pose[:3, :3] = (tilt * Rotation.from_rotvec([np.pi, 0, 0])).as_matrix()
        pose[:3, 3] = [rng.uniform(-0.15, 0.15), rng.uniform(-0.08, 0.08), rng.uniform(0.55, 0.7)]
        images.append(cam.render([TexturedPlane(texture, width, height, pose)], background=90.0))
    return images


def _check(model: CameraModel, rms: float) -> None:
    assert rms < 0.3
    assert model.matrix[0, 0] == pytest.approx(900.0, rel=0.01)
    assert model.matrix[0, 2] == pytest.approx(639.5, abs=5.0)
    # Distortion coefficients trade off against each other (k1 vs k2); what must agree
    # is the projection, over the part of the image the views covered.
    xs, ys = np.meshgrid(np.linspace(-0.4, 0.4, 9), np.linspace(-0.25, 0.25, 7))
    rays = np.c_[xs.ravel(), ys.ravel(), np.ones(xs.size)]
    # Tolerance: the principal point of a 10–16 view calibration is good to ~1–3 px.
    assert np.max(np.abs(model.project(rays) - TRUTH.project(rays))) < 3.0


def test_chessboard_calibration_recovers_intrinsics() -> None:
    cols, rows, square = 9, 6, 0.03  # inner corners; 10 x 7 squares
    px = 40
    tex = np.ones(((rows + 3) * px, (cols + 3) * px), np.float32)  # one square of margin
    for r in range(rows + 1):
        for c in range(cols + 1):
            if (r + c) % 2 == 0:
                tex[(r + 1) * px : (r + 2) * px, (c + 1) * px : (c + 2) * px] = 0.0
    w, h = (cols + 3) * square, (rows + 3) * square
    _check(*calibrate_chessboard(_views(tex, w, h), (cols, rows), square))


def test_charuco_calibration_recovers_intrinsics() -> None:
    squares, square, marker = (7, 5), 0.04, 0.03
    board = cv2.aruco.CharucoBoard(squares, square, marker, get_dictionary("DICT_4X4_50"))
    px, margin = 60, 30
    size = (squares[0] * px + 2 * margin, squares[1] * px + 2 * margin)
    tex = board.generateImage(size, marginSize=margin).astype(np.float32) / 255.0
    w, h = size[0] / px * square, size[1] / px * square
    # Fewer corners than the chessboard: more views for a comparable principal point.
    model, rms = calibrate_charuco(_views(tex, w, h, 16), squares, square, marker)
    _check(model, rms)


def test_too_few_views_and_bad_images() -> None:
    blank = [np.full((720, 1280), 128, np.uint8)] * 3
    with pytest.raises(VisionError, match="usable views"):
        calibrate_chessboard(blank, (9, 6), 0.03)
    with pytest.raises(VisionError, match="images\\[1\\]"):
        calibrate_charuco([blank[0], None], (7, 5), 0.04, 0.03)  # type: ignore[list-item]
    with pytest.raises(VisionError, match="shape"):
        calibrate_chessboard([blank[0], np.zeros((10, 10), np.uint8)], (9, 6), 0.03)
