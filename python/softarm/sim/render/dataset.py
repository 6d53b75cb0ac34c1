"""Labelled images of random rendered bushes, for training a detector: each image is one
random bush (4 to 12 berries, ripe and unripe) seen by C1's left or right eye or by C2
in the palm, with the arm drawn at a random pose or hidden, written with its depth, its
instance masks and a COCO record (boxes, polygons, ripeness, visible fraction, the
camera's intrinsics, distortion and pose). Everything is deterministic in the seed.

Files in the output folder (``NNNNNN`` is the image index):

* ``images/NNNNNN.png``: colour, 8-bit BGR as rendered (lens distortion included);
* ``depth/NNNNNN.png``: 16-bit depth along the optical axis in millimetres, 0 where
  nothing was drawn (aligned with the colour image);
* ``instances/NNNNNN.png``: 16-bit instance map, each annotation's ``instance`` value on
  its pixels, 0 elsewhere (the exact masks; the COCO polygons trace them);
* ``annotations.json``: COCO (``info``, ``images``, ``annotations``, ``categories``).

See docs/dataset.md for the format and its caveats.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm._core import SoftArm
from softarm.checks import FloatArray
from softarm.errors import ParameterError
from softarm.files import FreshFolder
from softarm.files.images import write_image
from softarm.sim.bush import Berry, Bush
from softarm.sim.render.coco import (
    CATEGORIES,
    ROW_CATEGORIES,
    category_id,
    mask_bbox,
    mask_polygons,
)
from softarm.sim.render.dataset_ray import on_ray, ray_or_none
from softarm.sim.render.renderer import RenderedFrame
from softarm.sim.render.row import STAGE_RIPENESS
from softarm.sim.render.row_look import LOOKS, RowLook
from softarm.sim.render.silhouette import silhouette_area
from softarm.sim.render.world import RenderedBush, arm_sections
from softarm.sim.world import WorldName
from softarm.vision.camera_model import CameraModel

__all__ = ["DatasetRig", "render_sample", "write_dataset"]

#: Views an image is drawn from, and how often.
VIEWS = ("c1_left", "c1_right", "c2")
VIEW_ODDS = (0.45, 0.25, 0.30)
#: How often a C1 image shows no arm.
ARM_HIDDEN_ODDS = 0.35
#: Berries per bush.
BERRIES = (4, 12)
#: A berry with fewer visible pixels than this is not annotated.
MIN_PIXELS = 4
#: Depth PNGs hold millimetres in 16 bits: at most 65.535 m.
DEPTH_SCALE = 1000.0
#: The COCO file of a set (and the mark of an earlier set a new one may replace).
ANNOTATIONS = "annotations.json"


@dataclass(frozen=True)
class DatasetRig:
    """The cameras and markers the bushes are rendered with (base frame; see
    :class:`~softarm.sim.render.RenderedBush`)."""

    T_base_c1: FloatArray
    c1: CameraModel
    c2: CameraModel
    T_ee_c2: FloatArray
    T_ee_cube: FloatArray
    T_base_tag: FloatArray
    base_tag_id: int
    base_tag: float
    #: "bush", the rendered bush; "row", the bush in a hedgerow in daylight
    #: (:mod:`softarm.sim.render.row`) with the look family ``look``
    #: (:data:`softarm.sim.render.row_look.LOOKS`) and its camera model.
    world_kind: WorldName = WorldName.BUSH
    look: str = "random"

    def __post_init__(self) -> None:
        world = WorldName.parse(self.world_kind)
        if not world.rendered:
            raise ParameterError(f"world must be 'bush' or 'row', got {self.world_kind!r}")
        object.__setattr__(self, "world_kind", world)
        if self.look not in LOOKS:
            raise ParameterError(f"look must be one of {', '.join(LOOKS)}, got {self.look!r}")

    def world(self, bush: Bush) -> RenderedBush:
        """``bush`` rendered with these cameras (in the row: a look of the family drawn
        from the bush's seed)."""
        look = RowLook.named(self.look, bush.seed) if self.world_kind is WorldName.ROW else None
        return RenderedBush(
            bush, self.T_base_c1, self.c1, self.c2, self.T_ee_c2, self.T_ee_cube,
            self.T_base_tag, self.base_tag_id, self.base_tag, look=look,
        )  # fmt: skip


@dataclass(frozen=True)
class _View:
    """One image's camera: its name, intrinsics and pose in the base frame."""

    name: str
    camera: CameraModel
    T_base_camera: FloatArray


def _random_bush(arm: SoftArm, rig: DatasetRig, rng: np.random.Generator) -> Bush:
    """4 to 12 berries, 20 to 60 % of them unripe (fewer berries if they do not fit)."""
    n = int(rng.integers(BERRIES[0], BERRIES[1] + 1))
    unripe = float(rng.uniform(0.2, 0.6))
    seed = int(rng.integers(2**31))
    for count in range(n, 0, -1):
        try:
            return Bush.generate(
                arm, count, seed, view_point=rig.T_base_c1[:3, 3], unripe_fraction=unripe
            )
        except ParameterError:
            continue
    raise ParameterError(f"could not place a bush of seed {seed}")


def _pose_arm(
    world: RenderedBush, arm: SoftArm, view: str, rng: np.random.Generator
) -> FloatArray | None:
    """Draw the arm for ``view``; returns its end-effector pose, None when hidden. C2 looks
    at a random berry from 1 to 10 % short of its grasp; C1 sees the arm at a random pose
    or none."""
    if view != "c2" and rng.uniform() < ARM_HIDDEN_ODDS:
        world.hide_arm()
        return None
    if view == "c2":
        berry = world.bush.berries[int(rng.integers(len(world.bush.berries)))]
        q = berry.q * rng.uniform(0.90, 0.99)
    else:
        q = rng.uniform(np.asarray(arm.lower), np.asarray(arm.upper))
    T_base_ee = arm.forward(q)
    world.set_arm(arm_sections(arm, q), T_base_ee)
    return T_base_ee


def _view(world: RenderedBush, rig: DatasetRig, name: str, T_base_ee: FloatArray | None) -> _View:
    stereo = world.stereo
    if name == "c1_left":
        return _View(name, stereo.left, stereo.T_base_left)
    if name == "c1_right":
        return _View(name, stereo.right, stereo.T_base_left @ stereo.T_left_right)
    assert T_base_ee is not None  # C2 always has the arm drawn
    return _View(name, world.c2, T_base_ee @ rig.T_ee_c2)


def _render(world: RenderedBush, view: str) -> RenderedFrame:
    if view == "c1_left":
        return world.c1_left(truth=True)
    if view == "c1_right":
        return world.c1(truth=True)[1]
    return world.c2_frame(truth=True)


def _berry_attributes(
    world: RenderedBush, berry: Berry, view: _View, pixels: int
) -> dict[str, Any]:
    renderer = world.renderer
    labels = world.labels
    geoms = np.flatnonzero((labels.kind == 1) & (labels.instance == berry.tag_id))
    full = silhouette_area(renderer.model, renderer.data, geoms, view.T_base_camera, view.camera)
    T_camera_base = np.linalg.inv(view.T_base_camera)
    in_camera = T_camera_base[:3, :3] @ berry.position + T_camera_base[:3, 3]
    stage = {} if world.row is None else {"stage": world.stage(berry.tag_id)}
    return {
        "berry_id": berry.tag_id,
        **stage,
        "ripeness": float(berry.ripeness),
        "visible_fraction": None if not full else round(min(1.0, pixels / full), 4),
        "position_base_m": [float(v) for v in berry.position],
        "position_camera_m": [float(v) for v in in_camera],
    }


def _cane_attributes(world: RenderedBush, index: int) -> dict[str, Any]:
    model = world.renderer.model
    radius = float(model.geom(f"cane{index}_0").size[0])
    coeffs = world.canes()[index].coeffs
    return {"cane_id": index, "radius_m": radius, "coeffs_base_m": coeffs.tolist()}


def _annotation(
    mask: npt.NDArray[np.bool_], category: str, attributes: dict[str, Any]
) -> dict[str, Any]:
    return {
        "category_id": category_id(category),
        "bbox": mask_bbox(mask),
        "area": int(np.count_nonzero(mask)),
        "segmentation": mask_polygons(mask),
        "iscrowd": 0,
        "attributes": attributes,
    }


def _annotate(
    world: RenderedBush, frame: RenderedFrame, view: _View
) -> list[tuple[npt.NDArray[np.bool_], dict[str, Any]]]:
    """(mask, annotation) of every berry with at least MIN_PIXELS visible and every cane
    in sight."""
    assert frame.geoms is not None
    out = []
    for berry in _fruit(world):
        mask = world.labels.mask(frame.geoms, "berry", berry.tag_id)
        pixels = int(np.count_nonzero(mask))
        if pixels >= MIN_PIXELS:
            category = _category(world, berry)
            out.append(
                (mask, _annotation(mask, category, _berry_attributes(world, berry, view, pixels)))
            )
    for index in range(len(world.canes())):
        mask = world.labels.mask(frame.geoms, "cane", index)
        if mask.any():
            out.append((mask, _annotation(mask, "cane", _cane_attributes(world, index))))
    return out


def _fruit(world: RenderedBush) -> list[Berry]:
    """Every fruit drawn, as berries (the row's: its stage's ripeness, no approach)."""
    if world.row is None:
        return list(world.bush.berries)
    bush = {b.tag_id: b for b in world.bush.berries}
    return [
        bush.get(f.fruit_id)
        or Berry(f.fruit_id, f.position, np.zeros(3), np.zeros(0), STAGE_RIPENESS[f.stage])
        for f in world.row.fruit
    ]


def _category(world: RenderedBush, berry: Berry) -> str:
    if world.row is not None and world.stage(berry.tag_id) == "turning":
        return "berry_turning"
    ripe = world.stage(berry.tag_id) == "ripe" if world.row is not None else berry.ripeness >= 0.5
    return "berry_ripe" if ripe else "berry_unripe"


def _write_png(path: Path, image: npt.NDArray[Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    write_image(path, image, "out: image")


def _depth_mm(depth: npt.NDArray[np.float32]) -> npt.NDArray[np.uint16]:
    mm = np.nan_to_num(depth * DEPTH_SCALE, nan=0.0)
    out: npt.NDArray[np.uint16] = np.clip(np.round(mm), 0, 65535).astype(np.uint16)
    return out


def _image_record(
    index: int, view: _View, frame: RenderedFrame, world: RenderedBush, arm_shown: bool
) -> dict[str, Any]:
    bush = world.bush
    name = f"{index:06d}.png"
    height, width = frame.colour.shape[:2]
    return {
        "id": index + 1,
        "file_name": f"images/{name}",
        "width": width,
        "height": height,
        "depth_file": f"depth/{name}",
        "instance_file": f"instances/{name}",
        "view": view.name,
        "arm_shown": arm_shown,
        "bush_seed": bush.seed,
        **_look_record(world),
        "camera": {
            "matrix": view.camera.matrix.tolist(),
            "distortion": np.ravel(view.camera.distortion).tolist(),
            "T_base_camera": view.T_base_camera.tolist(),
        },
    }


def _look_record(world: RenderedBush) -> dict[str, Any]:
    """The row's look (family, sun) for an image of the row; nothing for the bush."""
    look = world.look
    if not isinstance(look, RowLook):
        return {}
    return {
        "world": "row",
        "look": look.name,
        "sun_elevation_deg": round(look.sun_elevation, 2),
        "sun_azimuth_deg": round(look.sun_azimuth, 2),
    }


def render_sample(out_dir: str | Path, seed: int, index: int, rig: DatasetRig) -> dict[str, Any]:
    """Render image ``index`` of the set of ``seed``, write its files into ``out_dir`` and
    return ``{"image": COCO image record, "annotations": [...]}`` (annotation ids are
    given by :func:`write_dataset`)."""
    rng = np.random.default_rng([seed, index])
    arm = SoftArm.blackberry()
    bush = _random_bush(arm, rig, rng)
    view_name = str(rng.choice(VIEWS, p=VIEW_ODDS))
    world = rig.world(bush)
    try:
        T_base_ee = _pose_arm(world, arm, view_name, rng)
        frame = _render(world, view_name)
        view = _view(world, rig, view_name, T_base_ee)
        labelled = _annotate(world, frame, view)
    finally:
        world.close()
    assert frame.depth is not None
    instances = np.zeros(frame.colour.shape[:2], np.uint16)
    for k, (mask, annotation) in enumerate(labelled, start=1):
        instances[mask] = k
        annotation["instance"] = k
    out = Path(out_dir)
    record = _image_record(index, view, frame, world, T_base_ee is not None)
    _write_png(out / record["file_name"], frame.colour)
    _write_png(out / record["depth_file"], _depth_mm(frame.depth))
    _write_png(out / record["instance_file"], instances)
    for _, annotation in labelled:
        annotation["image_id"] = record["id"]
    return {"image": record, "annotations": [a for _, a in labelled]}


def ray_workers(images: int, workers: int | None) -> int:
    """How many Ray workers :func:`write_dataset` uses for ``images`` (all cores when
    ``workers`` is None); 0 when it renders in this process (Ray not installed, one
    worker, or fewer than three images: Ray's start would cost more than it saves)."""
    if workers is None:
        workers = os.cpu_count() or 1
    if workers < 2 or images < 3 or ray_or_none() is None:
        return 0
    return workers


def _coco(samples: list[dict[str, Any]], seed: int, rig: DatasetRig) -> dict[str, Any]:
    from softarm import __version__

    annotations = [a for s in samples for a in s["annotations"]]
    for k, annotation in enumerate(annotations, start=1):
        annotation["id"] = k
    return {
        "info": {
            "description": "softarm rendered blackberry bushes (softarm dataset)",
            "version": __version__,
            "softarm_version": __version__,
            "seed": seed,
            "images": len(samples),
            "depth_unit_m": 1.0 / DEPTH_SCALE,
        },
        "images": [s["image"] for s in samples],
        "annotations": annotations,
        "categories": ROW_CATEGORIES if rig.world_kind is WorldName.ROW else CATEGORIES,
    }


def write_dataset(
    out_dir: str | Path,
    images: int,
    seed: int,
    rig: DatasetRig,
    workers: int | None = None,
    on_image: Callable[[], None] = lambda: None,
) -> dict[str, Any]:
    """Render ``images`` labelled images of seed ``seed`` into ``out_dir`` and write
    ``annotations.json``; returns the COCO document. The set is written into a fresh
    folder beside ``out_dir`` and moved into place once complete (an earlier set there
    is replaced whole; a stop or failure leaves it as it was); a folder holding other
    files than a dataset is refused (:class:`~softarm.files.FreshFolder`). The first
    image is rendered here (a missing renderer is one clear
    :class:`RenderUnavailableError`), the others as Ray tasks over ``workers`` cores
    (default: all; :mod:`~softarm.sim.render.dataset_ray`) when Ray is installed and
    ``workers`` > 1, else one after the other. ``on_image`` is called after each image."""
    from softarm.files import write_text

    if images < 1:
        raise ParameterError(f"images must be >= 1, got {images}")
    if workers is not None and workers < 1:
        raise ParameterError(f"workers must be >= 1, got {workers}")
    with FreshFolder(out_dir, "dataset", ANNOTATIONS) as out:
        samples = [render_sample(out, seed, 0, rig)]
        on_image()
        rest = range(1, images)
        ray_cores = ray_workers(images, workers)
        if ray_cores:
            samples += on_ray(
                ray_or_none(), render_sample, out, seed, rest, rig, ray_cores, on_image
            )
        else:
            for i in rest:
                samples.append(render_sample(out, seed, i, rig))
                on_image()
        coco = _coco(samples, seed, rig)
        write_text(out / ANNOTATIONS, json.dumps(coco, separators=(",", ":")), ANNOTATIONS)
    return coco
