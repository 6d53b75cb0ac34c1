"""``softarm dataset``: two small labelled images, through the function and the command,
checked against the COCO format and the bush they were rendered from."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from render_required import need_mujoco, rendering
from softarm._core import SoftArm
from softarm.cli import main
from softarm.commands.dataset import default_rig
from softarm.sim.render import RenderUnavailableError, renderer
from softarm.sim.render.dataset import _random_bush, write_dataset

SEED = 5
SCALE = 0.25  # C1 320 x 180, C2 160 x 120


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    need_mujoco()
    out = tmp_path_factory.mktemp("dataset")
    with rendering():
        coco = write_dataset(out, 2, SEED, default_rig(SCALE), workers=1)
    return out, coco


def test_files_and_coco_structure(dataset: tuple[Path, dict[str, Any]]) -> None:
    out, coco = dataset
    assert json.loads((out / "annotations.json").read_text()) == coco
    assert coco["info"]["seed"] == SEED
    assert [c["name"] for c in coco["categories"]] == ["berry_ripe", "berry_unripe", "cane"]
    assert [im["id"] for im in coco["images"]] == [1, 2]
    ids = [a["id"] for a in coco["annotations"]]
    assert ids == list(range(1, len(ids) + 1))
    for im in coco["images"]:
        colour = cv2.imread(str(out / im["file_name"]), cv2.IMREAD_UNCHANGED)
        depth = cv2.imread(str(out / im["depth_file"]), cv2.IMREAD_UNCHANGED)
        assert colour.shape == (im["height"], im["width"], 3)
        assert depth.dtype == np.uint16 and depth.shape == colour.shape[:2]
        assert 300 < np.median(depth[depth > 0]) < 5000  # millimetres
        assert np.array(im["camera"]["matrix"]).shape == (3, 3)
        assert np.array(im["camera"]["T_base_camera"]).shape == (4, 4)


def test_boxes_and_masks(dataset: tuple[Path, dict[str, Any]]) -> None:
    out, coco = dataset
    images = {im["id"]: im for im in coco["images"]}
    assert {a["category_id"] for a in coco["annotations"]} <= {1, 2, 3}
    for a in coco["annotations"]:
        im = images[a["image_id"]]
        x, y, w, h = a["bbox"]
        assert 0 <= x and 0 <= y and w >= 1 and h >= 1
        assert x + w <= im["width"] and y + h <= im["height"]
        assert a["segmentation"] and all(len(p) >= 6 and len(p) % 2 == 0 for p in a["segmentation"])
        instances = cv2.imread(str(out / im["instance_file"]), cv2.IMREAD_UNCHANGED)
        mask = instances == a["instance"]
        assert a["area"] == np.count_nonzero(mask) > 0
        rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
        assert [x, y, w, h] == [cols[0], rows[0], cols[-1] + 1 - x, rows[-1] + 1 - y]


def test_berries_match_the_bush(dataset: tuple[Path, dict[str, Any]]) -> None:
    _, coco = dataset
    berries = [a for a in coco["annotations"] if a["category_id"] in (1, 2)]
    assert berries, "two random bushes show at least one berry"
    rig = default_rig(SCALE)
    for index, im in enumerate(coco["images"]):
        bush = _random_bush(SoftArm.blackberry(), rig, np.random.default_rng([SEED, index]))
        assert bush.seed == im["bush_seed"]
        truth = {b.tag_id: b for b in bush.berries}
        for a in (a for a in berries if a["image_id"] == im["id"]):
            berry = truth[a["attributes"]["berry_id"]]
            assert a["attributes"]["ripeness"] == berry.ripeness
            assert a["category_id"] == (1 if berry.ripeness >= 0.5 else 2)
            assert np.allclose(a["attributes"]["position_base_m"], berry.position)
            assert 0.0 < a["attributes"]["visible_fraction"] <= 1.0


def test_command_writes_the_same_set(
    dataset: tuple[Path, dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, coco = dataset
    args = ["dataset", "--out", str(tmp_path), "--images", "2", "--seed", str(SEED)]
    assert main([*args, "--scale", str(SCALE), "--workers", "1", "-q"]) == 0
    assert "2 images" in capsys.readouterr().out
    assert json.loads((tmp_path / "annotations.json").read_text()) == coco
    first = coco["images"][0]["file_name"]
    assert (tmp_path / first).read_bytes() == (out / first).read_bytes()


@pytest.mark.parametrize(
    ("option", "value"), [("--images", "0"), ("--scale", "0"), ("--workers", "0"), ("--seed", "-1")]
)
def test_bad_arguments_are_one_line(
    option: str, value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = {"--out": str(tmp_path), "--images": "2", option: value}
    with pytest.raises(SystemExit) as exit_:
        main(["dataset", *(s for kv in args.items() for s in kv)])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.count("\n") == 1 and option in err


def test_no_renderer_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def unavailable() -> None:
        raise RenderUnavailableError(renderer.HOW_TO_ENABLE)

    monkeypatch.setattr(renderer, "require_mujoco", unavailable)
    assert main(["dataset", "--out", str(tmp_path), "--images", "1", "-q"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "MUJOCO_GL=egl" in err


@pytest.mark.slow
def test_ray_writes_the_same_set_as_a_loop(tmp_path: Path) -> None:
    need_mujoco()
    pytest.importorskip("ray")
    rig = default_rig(SCALE)
    loop = write_dataset(tmp_path / "loop", 3, SEED, rig, workers=1)
    on_ray = write_dataset(tmp_path / "ray", 3, SEED, rig, workers=2)
    assert on_ray == loop
