"""Tiny labelled scenes for the learned detector's tests: discs of fruit colour on leaf
green, written as a COCO folder the way ``softarm dataset`` (instance PNGs) or CVAT
(polygons) writes one."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np

BACKGROUND = (60, 110, 70)  # BGR: leaf green
COLOURS = {"ripe": (40, 8, 25), "unripe": (30, 30, 200), "turning": (35, 20, 120)}
CATEGORIES = [
    {"id": 1, "name": "berry_ripe"},
    {"id": 2, "name": "berry_unripe"},
    {"id": 3, "name": "cane"},
    {"id": 4, "name": "berry_turning"},
]
_IDS = {"ripe": 1, "unripe": 2, "cane": 3, "turning": 4}
W, H = 160, 120


def disc(cx: int, cy: int, r: int) -> np.ndarray:
    yy, xx = np.mgrid[:H, :W]
    return np.asarray((xx - cx) ** 2 + (yy - cy) ** 2 <= r**2)


def sphere_depth(
    cx: int, cy: int, r_px: int, surface_m: float, focal: float, behind_m: float = 0.2
) -> np.ndarray:
    """(H, W) depth (m) of a sphere whose outline is the disc (cx, cy, r_px) and whose
    near surface is ``surface_m`` away (a fruit's cap; orthographic, small angles), in
    front of a wall ``behind_m`` farther."""
    radius = r_px * surface_m / focal
    yy, xx = np.mgrid[:H, :W]
    rho = np.hypot(xx - cx, yy - cy) * surface_m / focal
    depth = np.full((H, W), surface_m + behind_m)
    inside = rho <= radius
    depth[inside] = surface_m + radius - np.sqrt(radius**2 - rho[inside] ** 2)
    return depth


def polygon(mask: np.ndarray) -> list[list[float]]:
    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    return [[float(v) for v in c.reshape(-1)] for c in contours]


def draw(fruit: list[tuple[str, np.ndarray]], cane: np.ndarray | None = None) -> np.ndarray:
    img = np.full((H, W, 3), BACKGROUND, np.uint8)
    if cane is not None:
        img[cane] = (40, 70, 110)
    for stage, mask in fruit:
        img[mask] = COLOURS[stage]
    return img


def write_folder(
    folder: Path, scenes: list[list[tuple[str, np.ndarray, bool]]], instances: bool = True
) -> Path:
    """Write each scene (a list of (stage, mask, drawn)) as an image with its labels; an
    undrawn object is labelled but not in the picture (a fruit the detector cannot find).
    Returns the COCO file."""
    (folder / "images").mkdir(parents=True, exist_ok=True)
    (folder / "instances").mkdir(exist_ok=True)
    images: list[dict[str, Any]] = []
    annotations: list[dict[str, Any]] = []
    for k, scene in enumerate(scenes):
        cane = next((m for s, m, d in scene if s == "cane" and d), None)
        img = draw([(s, m) for s, m, d in scene if d and s != "cane"], cane)
        name = f"{k:06d}.png"
        cv2.imwrite(str(folder / "images" / name), img)
        inst = np.zeros((H, W), np.uint16)
        record: dict[str, Any] = {
            "id": k + 1,
            "file_name": f"images/{name}",
            "width": W,
            "height": H,
        }
        if instances:
            record["instance_file"] = f"instances/{name}"
        for j, (stage, mask, _) in enumerate(scene, start=1):
            inst[mask] = j
            x, y, w, h = cv2.boundingRect(mask.astype(np.uint8))
            annotations.append({
                "id": len(annotations) + 1, "image_id": k + 1, "category_id": _IDS[stage],
                "bbox": [x, y, w, h], "area": int(mask.sum()), "iscrowd": 0,
                "segmentation": polygon(mask), "instance": j,
            })  # fmt: skip
        cv2.imwrite(str(folder / "instances" / name), inst)
        images.append(record)
    coco = {"images": images, "annotations": annotations, "categories": CATEGORIES}
    path = folder / "annotations.json"
    path.write_text(json.dumps(coco))
    return path


def training_scenes(n: int, seed: int) -> list[list[tuple[str, np.ndarray, bool]]]:
    """``n`` random scenes of two to four fruit and a cane."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        cane = np.zeros((H, W), bool)
        x = int(rng.integers(20, W - 20))
        cane[:, x : x + 4] = True
        scene: list[tuple[str, np.ndarray, bool]] = [("cane", cane, True)]
        for _ in range(int(rng.integers(2, 5))):
            stage = str(rng.choice(["ripe", "unripe", "turning"]))
            c = (int(rng.integers(15, W - 15)), int(rng.integers(15, H - 15)))
            scene.append((stage, disc(*c, int(rng.integers(6, 12))) & ~cane, True))
        out.append(scene)
    return out
