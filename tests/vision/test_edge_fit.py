"""The blurred-step fit of an edge's profile (softarm.vision.edge_fit) against its
definition: on a straight edge rendered analytically (Gaussian PSF, area-sampled, read
bilinearly across as the corner refinement reads it) it recovers the edge's position
without noise, and with the camera's noise its spread is under the gradient centroid's
on the same draws (the centroid weighs every sample's noise alike, the fit the ramp's)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.vision.edge_fit import fit_edges

SS = 16  # supersampling of the analytic render
H = 48  # px: the image
STEP = 0.25  # px between profile samples (the refinement's)


def _edge_image(pos: float, angle_deg: float, ink: float, paper: float, blur: float) -> np.ndarray:
    """An edge through pixel (``pos``, H/2 - 0.5) (OpenCV's centres), ``angle_deg`` from
    vertical, ink on its left; a Gaussian PSF of ``blur`` px, area-sampled."""
    n = H * SS
    yy, xx = (np.mgrid[0:n, 0:n].astype(np.float32) + 0.5) / SS  # pixel-edge coordinates
    t = np.deg2rad(angle_deg)
    distance = (xx - (pos + 0.5)) * np.cos(t) - (yy - H / 2) * np.sin(t)
    big = np.where(distance > 0, paper, ink).astype(np.float32)
    big = cv2.GaussianBlur(big, (0, 0), blur * SS)
    image: np.ndarray = big.reshape(H, SS, H, SS).mean(axis=(1, 3))
    return image


def _profiles(
    image: np.ndarray, pos: float, angle_deg: float, half: float, off: float = 0.0
) -> tuple:
    """Profiles across the edge at 25 points 1 px apart along a line ``off`` px from it
    (along its normal, towards the paper), each ``half`` px to either side, and their
    offsets."""
    t = np.deg2rad(angle_deg)
    normal, along = np.array([np.cos(t), -np.sin(t)]), np.array([np.sin(t), np.cos(t)])
    offsets = STEP * np.arange(-round(half / STEP), round(half / STEP) + 1)
    centre = np.array([pos, H / 2 - 0.5]) + off * normal
    at = np.arange(-12, 13)
    pts = centre + at[:, None, None] * along + offsets[None, :, None] * normal
    prof = cv2.remap(image.astype(np.float32), pts.astype(np.float32), None, cv2.INTER_LINEAR)
    return prof.astype(np.float64), offsets


def _centroid(prof: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    grad = np.diff(prof, axis=1)
    mid = 0.5 * (offsets[1:] + offsets[:-1])
    result: np.ndarray = (grad @ mid) / grad.sum(axis=1)
    return result


@pytest.mark.parametrize("angle", [7.0, 30.0])
@pytest.mark.parametrize("shift", [-0.6, 0.0, 0.37])
def test_fit_recovers_a_clean_edge(angle: float, shift: float) -> None:
    pos = 23.0 + shift
    image = _edge_image(pos, angle, 20.0, 200.0, 0.7)
    # Profiles centred off the edge (as a detection's corners put them): the fit finds it.
    prof, offsets = _profiles(image, pos, angle, 4.0, off=0.3)
    start = _centroid(prof, offsets)
    found, ok = fit_edges(prof, offsets, start)
    assert ok.all()
    assert np.max(np.abs(found - (-0.3))) < 0.02


def test_fit_from_a_poor_start() -> None:
    image = _edge_image(23.2, 12.0, 40.0, 180.0, 1.0)
    prof, offsets = _profiles(image, 23.2, 12.0, 4.0)
    found, ok = fit_edges(prof, offsets, np.full(prof.shape[0], 0.8))
    assert ok.all()
    assert np.max(np.abs(found)) < 0.02


def test_a_flat_profile_is_refused() -> None:
    offsets = STEP * np.arange(-16, 17)
    flat = np.full((20, offsets.size), 90.0) + np.random.default_rng(0).normal(0, 1.0, (20, 33))
    start = np.linspace(-1.0, 1.0, 20)
    found, ok = fit_edges(flat, offsets, start)
    assert not ok.any()
    assert np.array_equal(found, start)  # a refused profile keeps the start


@pytest.mark.parametrize(("noise", "jpeg"), [(2.0, None), (2.0, 80)])
def test_fit_spreads_less_than_the_centroid(noise: float, jpeg: int | None) -> None:
    pos, angle = 23.37, 7.0
    light = _edge_image(pos, angle, 20.0, 200.0, 0.7)
    rng = np.random.default_rng(3)
    side_centroid, side_fit = [], []
    for _ in range(30):
        noisy = np.clip(np.round(light + noise * rng.standard_normal(light.shape)), 0, 255)
        image = noisy.astype(np.uint8)
        if jpeg is not None:
            data = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, jpeg])[1]
            image = cv2.imdecode(data, cv2.IMREAD_GRAYSCALE)
        prof, offsets = _profiles(image.astype(np.float64), pos, angle, 4.0)
        start = _centroid(prof, offsets)
        side_centroid.append(start.mean())
        side_fit.append(fit_edges(prof, offsets, start)[0].mean())
    # A side's mean edge (what its line is fitted to) over the draws: the fit's spread
    # is under two thirds of the centroid's (about half on these draws), unbiased.
    assert np.std(side_fit) < 0.67 * np.std(side_centroid)
    assert abs(np.mean(side_fit)) < 0.01
