"""Canes as curves (planning paper eq. 10): the fit against known cubics, the cane map
on a small rendered bush, and bad inputs."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.errors import VisionError
from softarm.perception.cane_curves import (
    CurveSearch,
    arc_length_cubic,
    curve_points,
    split_into_curves,
)
from softarm.perception.cane_metrics import cane_map_error
from softarm.perception.cane_pixels import stereo_disparity
from softarm.perception.canes import CaneFit, fit_canes
from softarm.vision.camera_model import CameraModel
from softarm.vision.stereo_camera import StereoCamera

KNOWN = [
    np.array([[0.1, 0.2, -0.05, 0.02], [0.5, 0.01, 0.03, -0.01], [0.2, 0.05, 0.04, 0.0]]),
    np.array([[-0.1, 0.02, 0.03, 0.01], [0.55, 0.02, -0.02, 0.01], [0.1, 0.2, -0.03, -0.02]]),
]


class _Cane:
    def __init__(self, coeffs: np.ndarray) -> None:
        self.coeffs = coeffs


def _noisy(coeffs: np.ndarray, n: int, noise: float, rng: np.random.Generator) -> np.ndarray:
    return curve_points(coeffs, u=rng.uniform(0, 1, n)) + rng.normal(0, noise, (n, 3))


@pytest.mark.parametrize("coeffs", KNOWN)
def test_the_cubic_through_noisy_points_is_the_known_curve(coeffs: np.ndarray) -> None:
    rng = np.random.default_rng(1)
    fitted = arc_length_cubic(_noisy(coeffs, 600, 0.001, rng))
    truth = _Cane(coeffs)
    scores = cane_map_error([_Cane(fitted)], [truth], workspace=5.0)
    assert scores["coverage"] > 0.98
    assert scores["median_mm"] < 0.5 and scores["p95_mm"] < 1.5
    # Either direction along the cane is the same obstacle: compare the end points.
    ends = curve_points(fitted, 2)
    true_ends = curve_points(coeffs, 2)
    gap = min(np.abs(ends - true_ends).max(), np.abs(ends[::-1] - true_ends).max())
    assert gap < 0.004


def test_points_of_two_canes_and_clutter_split_into_two_canes() -> None:
    rng = np.random.default_rng(2)
    clutter = rng.uniform([-0.2, 0.4, 0.0], [0.4, 0.7, 0.4], (150, 3))
    points = np.vstack([_noisy(c, 400, 0.0015, rng) for c in KNOWN] + [clutter])
    groups = split_into_curves(points, CurveSearch())
    fits = [_Cane(arc_length_cubic(points[g])) for g in groups]
    scores = cane_map_error(fits, [_Cane(c) for c in KNOWN], workspace=5.0)
    assert len(groups) == 2
    assert scores["coverage"] > 0.95 and scores["median_mm"] < 1.0
    assert scores["precision"] > 0.95


def _hidden_middle(
    coeffs: np.ndarray, hole: tuple[float, float], rng: np.random.Generator
) -> np.ndarray:
    """Points of a cane with the stretch ``hole`` (u range) hidden, as a leaf does."""
    u = rng.uniform(0, 1, 800)
    u = u[(u < hole[0]) | (u > hole[1])]
    return curve_points(coeffs, u=u) + rng.normal(0, 0.0015, (len(u), 3))


def test_the_two_visible_pieces_of_a_cane_behind_a_leaf_are_one_cane() -> None:
    rng = np.random.default_rng(3)
    coeffs = np.array([[0.0, 0.4, 0.0, 0.0], [0.5, 0.05, -0.03, 0.0], [0.1, 0.1, -0.02, 0.0]])
    length = float(np.sum(np.linalg.norm(np.diff(curve_points(coeffs), axis=0), axis=1)))
    hole = (0.45, 0.45 + 0.12 / length)  # 12 cm hidden: beyond the growth's max_gap
    points = _hidden_middle(coeffs, hole, rng)
    search = CurveSearch()
    assert search.max_gap < 0.12 <= search.join_gap
    groups = split_into_curves(points, search)
    assert len(groups) == 1
    scores = cane_map_error([_Cane(arc_length_cubic(points[groups[0]]))], [_Cane(coeffs)], 5.0)
    assert scores["coverage"] > 0.95 and scores["median_mm"] < 1.5


def test_pieces_of_two_canes_one_above_the_other_stay_two() -> None:
    rng = np.random.default_rng(4)
    a = np.array([[0.0, 0.15, 0.0, 0.0], [0.5, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
    b = a + np.array([[0.1], [0.0], [0.06]])  # 6 cm above, overlapping along x: no ends face
    points = np.vstack([_noisy(c, 300, 0.001, rng) for c in (a, b)])
    groups = split_into_curves(points, CurveSearch())
    assert len(groups) == 2
    for group in groups:  # each holds one cane's points, all but the odd speck
        assert len(np.unique(group // 300)) == 1 and len(group) >= 290


def test_a_cane_is_not_grown_across_a_hole_to_a_few_specks() -> None:
    # Three stray points 8 cm past a cane's end: with specks allowed (speck_points=1,
    # every point its own neighbour) the cubic reaches out to them; by default it stops
    # where the cane's points do.
    rng = np.random.default_rng(6)
    cane = np.array([[0.0, 0.3, 0.0, 0.0], [0.5, 0.0, 0.02, 0.0], [0.1, 0.0, 0.0, 0.0]])
    points = np.vstack([_noisy(cane, 400, 0.001, rng), curve_points(cane, u=[1.26, 1.27, 1.28])])
    end = curve_points(cane, u=[1.0])[0]

    def farthest_reach(search: CurveSearch) -> float:
        (group,) = split_into_curves(points, search)
        ends = curve_points(arc_length_cubic(points[group]), u=[0.0, 1.0])
        return float(np.max(ends[:, 0])) - end[0]

    assert farthest_reach(CurveSearch(speck_points=1)) > 0.07
    assert farthest_reach(CurveSearch()) < 0.01


def test_the_disparity_of_a_thin_cane_is_its_own_not_the_backdrops(stereo: StereoCamera) -> None:
    # A shaded 5-pixel tube 1 m away, before a textured backdrop at 1.4 m: strong SGBM
    # smoothing would give the tube the backdrop's disparity.
    rect = stereo.rectification
    fb = rect.focal * rect.baseline
    d_bar, d_backdrop = round(fb / 1.0), round(fb / 1.4)
    rng = np.random.default_rng(5)
    texture = rng.integers(0, 255, (480, 900)).astype(np.uint8)
    blurred = cv2.GaussianBlur(texture, (0, 0), 1.0)
    backdrop = np.repeat(blurred[:, :, None], 3, axis=2).astype(np.uint8)
    left = backdrop[:, 100:740].copy()
    right = backdrop[:, 100 + d_backdrop : 740 + d_backdrop].copy()
    tube = (np.array([0.6, 0.9, 1.0, 0.8, 0.5])[:, None] * [40, 120, 110]).astype(np.uint8)
    mask = np.zeros((480, 640), bool)
    for y in range(100, 400):
        x = 300 + (3 * (y - 100)) // 10
        left[y, x : x + 5] = tube
        right[y, x - d_bar : x - d_bar + 5] = tube
        mask[y, x : x + 5] = True
    disparity = stereo_disparity(left, right, rect, mask, (0.6, 1.5))
    assert np.mean(np.abs(disparity[mask] - d_bar) <= 1.0) > 0.85


def _shaded_tube(left: np.ndarray, right: np.ndarray, x: int, disparity: int) -> np.ndarray:
    """A 5-pixel vertical tube at column ``x`` of ``left`` and ``x - disparity`` of
    ``right`` (rows 100-399) on a textured backdrop; its mask in ``left``."""
    tube = (np.array([0.6, 0.9, 1.0, 0.8, 0.5])[:, None] * [40, 120, 110]).astype(np.uint8)
    mask = np.zeros(left.shape[:2], bool)
    left[100:400, x : x + 5] = tube
    right[100:400, x - disparity : x - disparity + 5] = tube
    mask[100:400, x : x + 5] = True
    return mask


def _textured_pair(width: int, shift: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(6)
    noise = rng.integers(0, 255, (480, width + shift)).astype(np.uint8)
    texture = cv2.GaussianBlur(noise, (0, 0), 1.0)
    backdrop = np.repeat(texture[:, :, None], 3, axis=2).astype(np.uint8)
    return backdrop[:, shift:].copy(), backdrop[:, :width].copy()


def test_a_cane_at_the_images_left_edge_is_matched(stereo: StereoCamera) -> None:
    # SGBM matches nothing in the first 184 columns of its input (the disparity span
    # here): the crop is padded past the image's edge instead of failing inside OpenCV
    # or leaving the cane unmatched.
    rect = stereo.rectification
    d_bar = round(rect.focal * rect.baseline / 1.4)
    left, right = _textured_pair(640, round(rect.focal * rect.baseline / 1.5))
    mask = _shaded_tube(left, right, 100, d_bar)
    disparity = stereo_disparity(left, right, rect, mask, (0.6, 1.5))
    assert np.mean(np.abs(disparity[mask] - d_bar) <= 1.0) > 0.85


def test_an_image_narrower_than_the_disparity_span_still_matches() -> None:
    K = np.array([[900.0, 0, 80], [0, 900.0, 240], [0, 0, 1]])
    camera = CameraModel(K, np.zeros(5), image_size=(160, 480))
    T_left_right = np.eye(4)
    T_left_right[0, 3] = 0.12
    narrow = StereoCamera(camera, camera, np.eye(4), T_left_right)
    left, right = _textured_pair(160, 80)
    mask = _shaded_tube(left, right, 100, 80)
    disparity = stereo_disparity(left, right, narrow.rectification, mask, (0.6, 1.5))
    assert np.mean(np.abs(disparity[mask] - 80) <= 1.0) > 0.85


def test_the_map_error_of_no_fit_is_no_coverage() -> None:
    scores = cane_map_error([], [_Cane(KNOWN[0])], workspace=5.0)
    assert scores["coverage"] == 0.0 and np.isnan(scores["median_mm"])


@pytest.mark.parametrize(
    ("left", "right", "depth", "names"),
    [
        (np.zeros((0, 0, 3), np.uint8), "ok", None, "left"),
        ("ok", np.zeros((480, 640, 3), np.float32), None, "right"),
        ("ok", np.zeros((240, 320, 3), np.uint8), None, "right"),
        ([[0]], "ok", None, "left"),
        ("ok", None, None, "right"),
        ("ok", None, np.zeros((480, 640), np.uint16), "depth"),
        ("ok", None, np.zeros((480, 320), np.float32), "depth"),
    ],
)
def test_bad_inputs_name_the_argument(stereo: StereoCamera, left, right, depth, names) -> None:
    ok = np.zeros((480, 640, 3), np.uint8)
    left = ok if isinstance(left, str) else left
    right = ok if isinstance(right, str) else right
    with pytest.raises(VisionError, match=names):
        fit_canes(left, right, stereo, depth=depth)


def test_no_cane_in_view_is_an_empty_list(stereo: StereoCamera) -> None:
    grey = np.full((480, 640, 3), 90, np.uint8)
    assert fit_canes(grey, grey, stereo) == []
    assert fit_canes(grey, None, stereo, depth=np.full((480, 640), np.nan, np.float32)) == []


#: The rendered bush the cane-map accuracy is judged on: from the seeds reserved for CI
#: (90000-90999, never tuned on nor reported: docs/architecture.md, "Seeds").
CANE_SEED = 90000


@pytest.fixture(scope="module")
def rendered():
    from render_required import need_mujoco, rendering

    need_mujoco()
    import softarm
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.bush import Bush
    from softarm.sim.render import RenderedBush
    from softarm.sim.rig_cameras import BASE_TAG_ID

    arm = softarm.SoftArm.blackberry()
    cams = default_cameras()
    bush = Bush.generate(arm, 4, CANE_SEED, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.4)
    with rendering():
        world = RenderedBush(
            bush, cams.T_base_c1, cams.model(1), cams.model(2), cams.T_ee_c2,
            cams.T_ee_cube, cams.T_base_tag, BASE_TAG_ID, cams.base_tag,
        )  # fmt: skip
    left, right = world.c1(truth=True)
    yield bush, world.stereo, left, right
    world.close()


def test_the_cane_map_of_a_rendered_bush_is_within_bounds(rendered) -> None:
    bush, stereo, left, right = rendered
    fits = fit_canes(left.colour, right.colour, stereo)
    assert fits and all(isinstance(f, CaneFit) for f in fits)
    assert all(0.001 < f.radius < 0.006 and f.support == len(f.points) for f in fits)
    scores = cane_map_error(fits, bush.branches)
    assert scores["median_mm"] < 4.0
    assert scores["coverage"] > 0.7


def test_an_aligned_depth_image_gives_the_same_canes(rendered) -> None:
    bush, stereo, left, _ = rendered
    fits = fit_canes(left.colour, None, stereo, depth=left.depth)
    scores = cane_map_error(fits, bush.branches)
    assert scores["median_mm"] < 3.0
    assert scores["coverage"] > 0.7
