"""From the network's per-pixel output to berries: fruit pixels (ripe, turning and unripe
together) split into connected parts; a part with two or more peaks of the centre
heatmap (fruit that touch) is split between them, each pixel going to its nearest peak
(the peaks found by the rule of the heatmap's kind, :data:`PEAK_RULES`; or, with
``DetectorSettings.split_touching``, at the necks of the part's shape: :mod:`.touching`);
the pieces of one fruit that a heatmap's split leaves are joined again and small weak
specks dropped, by the rule of the heatmap's kind (:mod:`.fragments`: the focal one's);
each instance's stage is the stage most of its pixels' probability says. Everything
runs at the network's resolution; each instance's mask is then resized to the image,
and placed and sized as :mod:`softarm.perception.berries` places and sizes its blobs."""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.perception.berries import (
    MAX_BLOBS,
    BerryDetection,
    DetectorSettings,
    Ripeness,
    _position,
)
from softarm.perception.detector.boundary import fruit_parts
from softarm.perception.detector.depth_check import rejection
from softarm.perception.detector.distance import distance_pieces
from softarm.perception.detector.fragments import (
    FRAGMENT_RULES,
    FragmentRule,
    grown,
    merge_fragments,
    speck,
)
from softarm.perception.detector.network import NetworkOutput
from softarm.perception.detector.size_split import SizeSplit
from softarm.perception.detector.touching import disc_seeds, split_discs
from softarm.vision.camera_model import CameraModel

__all__ = [
    "FRUIT_THRESHOLD",
    "PEAK_RULES",
    "RIPE_SHARE",
    "PeakRule",
    "StagedDetection",
    "instance_stage",
    "instances",
]

#: A pixel is fruit where the three stages' probabilities sum to more than this.
FRUIT_THRESHOLD = 0.5
#: A centre-heatmap peak must reach this to seed an instance. This and PEAK_SEPARATION
#: were chosen on validation renders of the training looks (dataset seed 100300), not on
#: the evaluation sets: the shipped network's heatmap is broad, and 0.35 split one fruit
#: into many (precision 0.03 there, against 0.26 at 0.6).
PEAK_THRESHOLD = 0.6
#: A focal-loss heatmap's peak rule (``softarm detector train --heatmap focal``): its
#: peaks are a pixel or two wide, one per fruit, so a peak of FOCAL_PEAK_THRESHOLD is a
#: fruit and two peaks FOCAL_PEAK_SEPARATION apart are two (touching fruit at C1's half
#: size lie 4-12 network px apart, inside PEAK_SEPARATION). Chosen on the validation
#: renders (dataset seed 100300), not on the evaluation sets: thresholds 0.1-0.3 found
#: more ripe fruit but split fruit into fragments (precision with both checks 0.54-0.93
#: against 0.95-0.98 at 0.4); 0.5 split nothing; separations 1.5 and 4 changed little.
FOCAL_PEAK_THRESHOLD = 0.4
FOCAL_PEAK_SEPARATION = 2.5
#: Fewest network pixels an instance may have (two or three image pixels across at the
#: network's scale: smaller parts are speckle, not fruit C1 could place).
MIN_PIXELS = 6
#: Two peaks closer than this (network px) are one fruit's.
PEAK_SEPARATION = 10.0
#: The least radius (network px, the distance map's height) of a second fruit in a part
#: (:mod:`.touching`): 5 image px at C1's half size. Chosen on the validation renders
#: (dataset seed 100300): 1.5 found the same ripe fruit with more fragments.
SEED_RADIUS = 2.5
#: An instance is ripe when ripe holds this share of its stage probability mass (chosen
#: on the validation renders, dataset seed 100300, sun, overcast and dusk: stage right
#: 0.78 by plurality, 0.89 at 0.5, 0.93 at 0.6, 0.92 at 0.65 there).
RIPE_SHARE = 0.6
_U8 = npt.NDArray[np.uint8]


@dataclass(frozen=True)
class PeakRule:
    """Which local maxima of a centre heatmap seed a fruit: at least ``threshold`` high
    and more than ``separation`` network px from a stronger one."""

    threshold: float
    separation: float


#: The peak rule of each heatmap kind (``NetworkOutput.heatmap``).
PEAK_RULES = {
    "logistic": PeakRule(PEAK_THRESHOLD, PEAK_SEPARATION),
    "focal": PeakRule(FOCAL_PEAK_THRESHOLD, FOCAL_PEAK_SEPARATION),
}


@dataclass(frozen=True)
class StagedDetection(BerryDetection):
    """A :class:`BerryDetection` with the fruit's ``stage`` ("ripe", "turning" or
    "unripe"; ``ripeness`` is "ripe" only for ripe, since turning fruit is not ripe)."""

    stage: str = "ripe"


def _peaks(
    centres: npt.NDArray[np.float32], part: npt.NDArray[np.bool_], rule: PeakRule
) -> list[tuple[int, int]]:
    """(row, col) of the heatmap's local maxima inside ``part`` that ``rule`` keeps."""
    grown = cv2.dilate(centres, np.ones((3, 3), np.uint8))
    rows, cols = np.nonzero(part & (centres >= grown) & (centres >= rule.threshold))
    order = np.argsort(-centres[rows, cols], kind="stable")
    kept: list[tuple[int, int]] = []
    for r, c in zip(rows[order].tolist(), cols[order].tolist(), strict=True):
        # A plateau or a ragged peak gives neighbours of one centre: keep the strongest.
        if all((r - kr) ** 2 + (c - kc) ** 2 > rule.separation**2 for kr, kc in kept):
            kept.append((r, c))
    return kept


def _split(
    part: npt.NDArray[np.bool_], peaks: list[tuple[int, int]]
) -> list[npt.NDArray[np.bool_]]:
    """``part`` divided between its ``peaks`` (each pixel to the nearest: discs of no
    radius)."""
    return split_discs(part, [(float(r), float(c), 0.0) for r, c in peaks])


def _pieces(
    part: npt.NDArray[np.bool_],
    centres: npt.NDArray[np.float32],
    split: bool,
    rule: PeakRule,
    fragments: FragmentRule | None = None,
    distance: npt.NDArray[np.float32] | None = None,
) -> list[npt.NDArray[np.bool_]]:
    """``part`` as one mask per fruit: at the necks of its distance map (``split``,
    :mod:`.touching`), else by the watershed of the network's normalised distance to the
    fruit's edge where it gives one (``distance``, the part's window: :mod:`.distance`),
    else at its centre heatmap's peaks (of ``rule``), the pieces that ``fragments`` calls
    one fruit joined again (:mod:`.fragments`)."""
    if split:
        # Too few pixels for two fruit of the least radius: one fruit, no distance map.
        if np.count_nonzero(part) < 2 * np.pi * SEED_RADIUS**2:
            return [part]
        return split_discs(part, disc_seeds(part, SEED_RADIUS))
    if distance is not None:
        return distance_pieces(part, distance)
    peaks = _peaks(centres, part, rule)
    return merge_fragments(_split(part, peaks), peaks, centres, fragments)


#: An instance at the network's resolution: its mask over its window, and the window's
#: (x, y) in the network's map.
Piece = tuple[npt.NDArray[np.bool_], int, int]


def instance_masks(
    output: NetworkOutput,
    fruit: npt.NDArray[np.float32],
    split: bool = False,
    sizes: SizeSplit | None = None,
) -> list[Piece]:
    """The fruit instances at the network's resolution (``fruit``: output.fruit()), fruit
    that touch split at the necks of their part's distance map (``split``) or at the
    centre heatmap's peaks, and a piece larger than a fruit at its depth cut into the
    fruit it holds (``sizes``, on the network's grid: :mod:`.size_split`)."""
    rule = PEAK_RULES[output.heatmap]
    fragments = FRAGMENT_RULES.get(output.heatmap)
    binary = cast(_U8, (fruit > FRUIT_THRESHOLD).astype(np.uint8))
    binary = cast(_U8, cv2.morphologyEx(binary, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8)))
    taken = binary > 0  # what a small piece may not grow into (.fragments.grown)
    # A network with the boundary class cuts touching fruit apart first (.boundary).
    n, labels, stats = fruit_parts(binary, output.boundary)
    out = []
    for k in range(1, n):
        x, y, w, h, area = (int(v) for v in stats[k])
        if area < MIN_PIXELS:
            continue
        part = labels[y : y + h, x : x + w] == k
        centres = output.centres[y : y + h, x : x + w]
        distance = None if output.distance is None else output.distance[y : y + h, x : x + w]
        for piece in _pieces(part, centres, split, rule, fragments, distance):
            for one in [piece] if sizes is None else sizes.pieces(piece, x, y):
                if np.count_nonzero(one) >= MIN_PIXELS and not speck(one, centres, fragments):
                    out.append(grown(one, x, y, fruit, taken, fragments))
    return out


def _sizes(
    output: NetworkOutput,
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None,
    settings: DetectorSettings,
) -> SizeSplit | None:
    """The size split on the network's grid (``settings.split_by_size`` with depth and
    its check): the depth taken at the nearest image pixel (no mixing of a fruit's
    depth with the background's across its edge), the focal length and the outline's
    allowance scaled to the grid."""
    if depth is None or not settings.split_by_size or settings.depth_check is None:
        return None
    net_h, net_w = output.centres.shape
    grid = cast(
        npt.NDArray[np.float32],
        cv2.resize(
            np.ascontiguousarray(depth, np.float32),
            (net_w, net_h),
            interpolation=cv2.INTER_NEAREST,
        ),
    )
    scale = net_w / output.size[0]
    check = settings.depth_check
    return SizeSplit(grid, camera.focal * scale, check, check.outline_px * scale)


def instances(
    output: NetworkOutput,
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None,
    settings: DetectorSettings,
) -> list[StagedDetection]:
    """The berries of ``output`` (for an image of ``output.size``), placed with ``depth``
    where it is given (and then only those that depth agrees are fruit:
    :mod:`.depth_check`)."""
    out = []
    fruit = output.fruit()
    sizes = _sizes(output, camera, depth, settings)
    pieces = instance_masks(output, fruit, settings.split_touching, sizes)
    if len(pieces) > MAX_BLOBS:  # a patterned frame of specks: the largest, bounded time
        pieces = sorted(pieces, key=lambda p: -int(np.count_nonzero(p[0])))[:MAX_BLOBS]
    for piece in pieces:
        det = _detection(output, fruit, piece, camera, depth, settings)
        if det is not None:
            out.append(det)
    return out


def instance_stage(stage_mass: npt.NDArray[np.floating]) -> tuple[str, float]:
    """An instance's stage from its (ripe, turning, unripe) probability mass, and its
    ripe share: ripe only when ripe holds RIPE_SHARE of the mass, else the larger of
    turning and unripe. The plurality (argmax) called a fruit ripe on a third of the
    mass when turning and unripe split the rest: on the validation renders it called 30
    of 70 turning or unripe fruit ripe, against 6 with RIPE_SHARE."""
    p_ripe = float(stage_mass[0] / max(float(stage_mass.sum()), 1e-9))
    if p_ripe >= RIPE_SHARE:
        return "ripe", p_ripe
    return ("turning" if stage_mass[1] >= stage_mass[2] else "unripe"), p_ripe


def _upsampled(output: NetworkOutput, piece: Piece) -> Piece | None:
    """``piece`` at the image's resolution: the mask over its box and the box's (x, y),
    resizing only the instance's own window (with a pixel to spare) as
    :meth:`NetworkOutput.upsample` resizes the whole map."""
    small, px, py = piece
    x, y, w, h = cv2.boundingRect(small.astype(np.uint8))
    net_h, net_w = output.centres.shape
    x0, y0 = max(px + x - 1, 0), max(py + y - 1, 0)
    x1, y1 = min(px + x + w + 1, net_w), min(py + y + h + 1, net_h)
    window = np.zeros((y1 - y0, x1 - x0), np.float32)
    wy, wx = py + y - y0, px + x - x0
    window[wy : wy + h, wx : wx + w] = small[y : y + h, x : x + w]
    width, height = output.size
    sx, sy = width / net_w, height / net_h
    ox, oy = round(x0 * sx), round(y0 * sy)
    size = (min(round(x1 * sx), width) - ox, min(round(y1 * sy), height) - oy)
    up = cv2.resize(window, size, interpolation=cv2.INTER_LINEAR) >= 0.5
    if not up.any():
        return None
    bx, by, bw, bh = cv2.boundingRect(up.astype(np.uint8))
    return np.ascontiguousarray(up[by : by + bh, bx : bx + bw]), ox + bx, oy + by


def _detection(
    output: NetworkOutput,
    fruit: npt.NDArray[np.float32],
    piece: Piece,
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None,
    s: DetectorSettings,
) -> StagedDetection | None:
    small, px, py = piece
    window = (slice(py, py + small.shape[0]), slice(px, px + small.shape[1]))
    stage_mass = output.probabilities[window][small][:, 1:4].sum(axis=0)
    stage, p_ripe = instance_stage(stage_mass)
    score = float(np.clip(fruit[window][small].mean(), 0.0, 1.0))
    upsampled = _upsampled(output, piece)
    if upsampled is None:
        return None
    # The instance's own box only, as berries.py keeps its blobs' masks.
    mask, bx, by = upsampled
    bh, bw = mask.shape
    box = (slice(by, by + bh), slice(bx, bx + bw))
    m = cv2.moments(mask.astype(np.uint8), binaryImage=True)
    cx, cy = bx + m["m10"] / m["m00"], by + m["m01"] / m["m00"]
    radius = float(np.sqrt(m["m00"] / np.pi))
    position = None
    if depth is not None:
        if s.depth_check is not None and rejection(
            mask, radius, depth[box], camera.focal, s.depth_check
        ):
            return None
        position = _position(mask, (cx, cy), radius, camera, depth[box])
    ripeness: Ripeness = "ripe" if stage == "ripe" else "unripe"
    return StagedDetection(
        center=(float(cx), float(cy)),
        radius=radius,
        box=(int(bx), int(by), int(bw), int(bh)),
        mask=mask,
        score=score,
        ripeness=ripeness,
        probability=p_ripe if ripeness == "ripe" else 1.0 - p_ripe,
        position=position,
        radius_m=None
        if position is None
        else radius * float(np.linalg.norm(position)) / camera.focal,
        mask_offset=(int(bx), int(by)),
        stage=stage,
    )
