"""A fruit's centre from its silhouette with the edge pixels counted by their share of
fruit (softarm.perception.berry_centre): a dark fruit half in front of a bright leaf and
half in front of dark ground, drawn with its edge pixels mixed in proportion to their
cover, is centred to a twelfth of a pixel, where the thresholded mask's centroid
leans towards the dark ground; a fruit brighter on its side towards the light is
centred to a seventh of a pixel, where one colour for the whole fruit leaned 0.6-0.75
px away from the light."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.perception.berries import MAX_REFINED_RADIUS, detect_berries
from softarm.perception.berry_centre import silhouette_centre
from softarm.vision.camera_model import CameraModel

CAMERA = CameraModel.ideal(300.0, 160, 120)
FRUIT = np.array([40.0, 8.0, 25.0])  # BGR: black-purple
LEAF = np.array([60.0, 150.0, 80.0])  # BGR: a lit leaf
GROUND = np.array([22.0, 30.0, 26.0])  # BGR: shaded ground


def fruit_image(centre: tuple[float, float], radius: float, split: float) -> np.ndarray:
    """A disc of fruit at ``centre`` (px) on the leaf left of column ``split`` and on the
    ground right of it; each pixel the mix of the two in the share the disc covers
    (8 x 8 samples a pixel, their centres at the pixel's integer coordinates)."""
    n = 8
    offsets = (np.arange(n) + 0.5) / n - 0.5
    yy, xx = np.mgrid[0:120, 0:160].astype(float)
    cover = np.zeros((120, 160))
    for dy in offsets:
        for dx in offsets:
            cover += (xx + dx - centre[0]) ** 2 + (yy + dy - centre[1]) ** 2 < radius**2
    cover /= n * n
    ground = np.where((xx < split)[..., None], LEAF, GROUND)
    image = cover[..., None] * FRUIT + (1.0 - cover[..., None]) * ground
    return np.asarray(np.round(image), np.uint8)


def mask_centroid(det: object) -> tuple[float, float]:
    """What the detector returned before: the centroid of the thresholded mask."""
    m = cv2.moments(det.mask.astype(np.uint8), binaryImage=True)  # type: ignore[attr-defined]
    ox, oy = det.mask_offset  # type: ignore[attr-defined]
    return ox + m["m10"] / m["m00"], oy + m["m01"] / m["m00"]


@pytest.mark.parametrize("centre", [(80.37, 60.62), (79.81, 58.15), (81.5, 61.05)])
def test_a_fruit_in_front_of_two_grounds_is_centred_where_it_is(
    centre: tuple[float, float],
) -> None:
    [det] = detect_berries(fruit_image(centre, 9.3, 80.0), CAMERA)
    old = mask_centroid(det)
    assert abs(old[0] - centre[0]) > 0.15  # the mask leans to the dark ground
    # 0.06 px with one colour for the whole fruit; its colour beside each edge pixel
    # (for shading) carries a little of the detector's blur: up to 0.075 px here.
    assert det.center == pytest.approx(centre, abs=0.08)


#: A rendered berry's colours on C1 (bush 1501): its unlit drupelets, its edge towards
#: the light, and the olive wall behind it.
DARK_FRUIT = np.array([12.0, 3.0, 10.0])
LIT_FRUIT = np.array([50.0, 30.0, 48.0])
WALL = np.array([29.0, 39.0, 44.0])


def shaded_fruit(
    centre: tuple[float, float], radius: float, light: tuple[float, float]
) -> np.ndarray:
    """A disc of fruit at ``centre`` (px) in front of the wall, brighter towards the
    image direction ``light`` (unit) as a fruit lit from that side is: its own dark
    colour at and beyond its middle, the lit edge's at its rim; each pixel the mix of
    fruit and wall in the share the disc covers (8 x 8 samples a pixel)."""
    n = 8
    offsets = (np.arange(n) + 0.5) / n - 0.5
    yy, xx = np.mgrid[0:120, 0:160].astype(float)
    image = np.zeros((120, 160, 3))
    for dy in offsets:
        for dx in offsets:
            ux, uy = (xx + dx - centre[0]) / radius, (yy + dy - centre[1]) / radius
            lit = np.clip(ux * light[0] + uy * light[1], 0.0, 1.0)[..., None]
            fruit = DARK_FRUIT + (LIT_FRUIT - DARK_FRUIT) * lit
            image += np.where((ux**2 + uy**2 < 1.0)[..., None], fruit, WALL)
    return np.asarray(np.round(image / (n * n)), np.uint8)


@pytest.mark.parametrize("light", [(0.0, -1.0), (0.6, -0.8), (-1.0, 0.0)])
@pytest.mark.parametrize("centre", [(80.37, 60.62), (79.81, 58.15), (81.5, 61.05)])
def test_a_shaded_fruit_is_centred_without_leaning_from_the_light(
    centre: tuple[float, float], light: tuple[float, float]
) -> None:
    # Its lit rim is brighter than the wall in blue and red, its middle darker than it:
    # measured against the middle's colour, the rim read as wall and the centre leaned
    # 0.6-0.75 px away from the light.
    [det] = detect_berries(shaded_fruit(centre, 9.3, light), CAMERA)
    error = np.subtract(det.center, centre)
    assert abs(float(error @ np.array(light))) < 0.15
    assert float(np.hypot(*error)) < 0.15


def test_without_contrast_the_mask_centroid_stands() -> None:
    # Fruit and ground of one brightness: nothing tells the edge's shares apart.
    mask = np.zeros((30, 30), bool)
    mask[10:20, 8:18] = True
    colour = np.full((30, 30, 3), 12, np.uint8)
    assert silhouette_centre(mask, colour, (100, 50), (112.5, 64.5)) == pytest.approx((112.5, 64.5))


def test_a_window_too_small_for_a_background_keeps_the_centroid() -> None:
    mask = np.ones((6, 6), bool)  # the fruit fills the window: no ring around it
    colour = np.zeros((6, 6, 3), np.uint8)
    assert silhouette_centre(mask, colour, (0, 0), (2.5, 2.5)) == (2.5, 2.5)


def test_a_close_up_fruit_keeps_its_masks_centroid() -> None:
    # 20 px: C2's close-up, where highlights on the lit edge would read as background.
    [det] = detect_berries(fruit_image((80.37, 60.62), 20.0, 80.0), CAMERA)
    assert det.radius > MAX_REFINED_RADIUS
    assert det.center == pytest.approx(mask_centroid(det), abs=1e-9)
