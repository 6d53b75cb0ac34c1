"""The daylight row (``--world row``): its ground truth, its shadows, its looks and the
``--look`` option. Rendered small (C1 at 320 x 180) to keep CI fast."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import softarm
from softarm.cli import main
from softarm.commands import _looks
from softarm.errors import ParameterError
from softarm.sim.bush import Bush
from softarm.sim.render.labels import KINDS
from softarm.sim.render.row import ROW_FRUIT_ID, STAGES
from softarm.sim.render.row_look import FAMILIES, LOOK_RANGES, LOOKS, RowLook, look_table

SEED = 4
SCALE = 0.25


def _world(look: RowLook, shadows: bool = True) -> Any:
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.render import RenderUnavailableError
    from softarm.sim.render.world import RenderedBush
    from softarm.sim.rig_cameras import BASE_TAG_ID

    pytest.importorskip("mujoco")
    cams = default_cameras(scale=SCALE)
    bush = Bush.generate(
        softarm.SoftArm.blackberry(), 6, SEED, view_point=cams.T_base_c1[:3, 3],
        unripe_fraction=0.4,
    )  # fmt: skip
    try:
        return RenderedBush(
            bush, cams.T_base_c1, cams.model(1), cams.model(2), cams.T_ee_c2, cams.T_ee_cube,
            cams.T_base_tag, BASE_TAG_ID, cams.base_tag, cams.cube_marker, look, shadows=shadows,
        )  # fmt: skip
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))


@pytest.fixture(scope="module")
def row() -> Any:
    world = _world(RowLook.named("sun", SEED))
    yield world
    world.close()


def test_ground_truth_is_exact(row: Any) -> None:
    frame = row.c1_left(truth=True)
    kinds = row.labels.kinds(frame.geoms)
    for kind in ("berry", "cane", "leaf", "clutter"):
        assert (kinds == KINDS.index(kind)).any(), kind
    berry = kinds == KINDS.index("berry")
    seen = set(np.unique(row.labels.instance[frame.geoms[berry]]).tolist())
    assert seen and all(row.stage(i) in STAGES for i in seen)
    assert any(i >= ROW_FRUIT_ID for i in seen) and any(i < ROW_FRUIT_ID for i in seen)
    assert 20 <= len(row.fruit_ids()) <= 90
    assert {row.stage(i) for i in row.fruit_ids()} == set(STAGES)
    shares = row.berry_shares(frame)
    assert set(shares) == set(row.fruit_ids())
    assert all(0.0 <= s <= 1.0 for s in shares.values())
    assert all(shares[i] > 0 for i in seen)
    # Depth where something is drawn, NaN where the sky is.
    assert np.isfinite(frame.depth[frame.geoms >= 0]).all()
    assert np.isnan(frame.depth[frame.geoms < 0]).all()


def test_the_bushs_canes_keep_their_ids(row: Any) -> None:
    canes = row.canes()
    assert canes[: len(row.bush.branches)] == row.bush.branches
    assert len(canes) > len(row.bush.branches)


def test_frames_are_repeatable_and_go_through_the_camera_model() -> None:
    look = RowLook.named("dusk", SEED)
    a, b = _world(look, shadows=False), _world(look, shadows=False)
    try:
        first, again = a.c1_left().colour, b.c1_left().colour
        assert np.array_equal(first, again)
        raw = a.renderer.render("c1_left").colour
        assert not np.array_equal(first, raw)  # noise, exposure, compression
        left, right = a.c1()
        assert left.colour.shape == right.colour.shape == first.shape
    finally:
        a.close()
        b.close()


def _pinhole_points(world: Any, depth: np.ndarray, pixels: np.ndarray) -> np.ndarray:
    """Base-frame points of ``pixels`` (N, 2: u, v) of C1's left pinhole render."""
    spec = world.renderer.cameras["c1_left"]
    u, v = pixels[:, 0], pixels[:, 1]
    z = depth[v, u].astype(float)
    rays = np.column_stack(
        [
            (u - spec.principal[0]) / spec.focal,
            (v - spec.principal[1]) / spec.focal,
            np.ones(len(u)),
        ]
    )
    T = np.asarray(world.stereo.T_base_left)
    points: np.ndarray = (rays * z[:, None]) @ T[:3, :3].T + T[:3, 3]
    return points


def _grey(image: np.ndarray, pixels: np.ndarray) -> np.ndarray:
    grey: np.ndarray = image[pixels[:, 1], pixels[:, 0]].astype(float).sum(axis=1)
    return grey


def test_the_shadowed_render_is_darker_where_the_sun_is_blocked() -> None:
    """Each sampled pixel's point is ray-cast towards the sun through the scene's
    geoms: where something is in the way, the render with shadows is darker than the
    one without; where nothing is, they agree."""
    import mujoco

    look = dataclasses.replace(
        RowLook.named("sun", SEED),
        light_direction=-np.array([0.35, -0.55, 0.76]) / np.linalg.norm([0.35, -0.55, 0.76]),
    )
    lit, flat = _world(look, shadows=True), _world(look, shadows=False)
    try:
        a = lit.renderer.render("c1_left", depth=True, geoms=True)
        b = flat.renderer.render("c1_left").colour
        v, u = np.nonzero(a.geoms >= 0)
        pick = np.random.default_rng(0).choice(len(u), 600, replace=False)
        pixels = np.column_stack([u[pick], v[pick]])
        points = _pinhole_points(lit, a.depth, pixels)
        model, data = lit.renderer.model, lit.renderer.data
        toward = -look.light_direction
        blocked = []
        hit = np.zeros(1, np.int32)
        groups = np.array([1, 1, 1, 0, 0, 0], np.uint8)
        for (uu, vv), p in zip(pixels, points, strict=True):
            d = mujoco.mj_ray(model, data, p + 0.01 * toward, toward, groups, 1, -1, hit)
            blocked.append(d >= 0 and hit[0] != a.geoms[vv, uu])
        blocked_ = np.array(blocked)
        ratio = (_grey(a.colour, pixels) + 1.0) / (_grey(b, pixels) + 1.0)
        assert blocked_.sum() > 30 and (~blocked_).sum() > 30
        assert np.median(ratio[blocked_]) < 0.8
        assert np.median(ratio[~blocked_]) > 0.95
        assert np.median(ratio[blocked_]) < np.median(ratio[~blocked_]) - 0.15
    finally:
        lit.close()
        flat.close()


def test_each_look_draws_within_its_ranges() -> None:
    for name in FAMILIES:
        for seed in range(5):
            look = RowLook.named(name, seed)
            assert look.name == name
            lo, hi = LOOK_RANGES[name]["sun_elevation"]
            assert lo <= look.sun_elevation <= hi
            lo, hi = LOOK_RANGES[name]["sun_intensity"]
            assert lo <= look.light_intensity <= hi
            assert look.light_direction[2] < 0  # the sun above the horizon
    assert {RowLook.named("random", s).name for s in range(40)} == set(FAMILIES)
    assert repr(RowLook.named("sun", 3)) == repr(RowLook.named("sun", 3))
    assert "| sun_elevation |" in look_table()


def test_the_command_line_knows_the_same_looks() -> None:
    assert _looks.LOOKS == LOOKS


def test_a_bad_look_is_one_clear_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(ParameterError, match="look"):
        RowLook.named("noon", 0)
    with pytest.raises(SystemExit) as exit_:
        main(["dataset", "--out", str(tmp_path / "d"), "--images", "1", "--world", "row",
              "--look", "noon"])  # fmt: skip
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.count("\n") == 1 and "--look" in err
    assert main(["dataset", "--out", str(tmp_path / "d"), "--images", "1", "--look", "sun"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--look" in err and "--world row" in err


def test_the_row_dataset_has_stages(tmp_path: Path) -> None:
    from softarm.commands.dataset import default_rig
    from softarm.sim.render import RenderUnavailableError
    from softarm.sim.render.dataset import write_dataset

    pytest.importorskip("mujoco")
    try:
        coco = write_dataset(tmp_path, 1, SEED, default_rig(SCALE, "row", "overcast"), workers=1)
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))
    names = {c["id"]: c["name"] for c in coco["categories"]}
    assert "berry_turning" in names.values()
    assert coco["images"][0]["look"] == "overcast"
    stages = {a["attributes"]["stage"] for a in coco["annotations"] if "stage" in a["attributes"]}
    assert stages <= set(STAGES) and len(stages) >= 2
    for a in coco["annotations"]:
        if "stage" in a["attributes"]:
            stage = a["attributes"]["stage"]
            want = {"ripe": "berry_ripe", "turning": "berry_turning"}.get(stage, "berry_unripe")
            assert names[a["category_id"]] == want
    assert json.loads((tmp_path / "annotations.json").read_text()) == coco


def test_harvest_takes_a_look_for_the_row_only(capsys: pytest.CaptureFixture[str]) -> None:
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    with pytest.raises(SystemExit) as exit_:
        main(["harvest", "--sim", "--world", "row", "--look", "noon"])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.count("\n") == 1 and "--look" in err
    assert main(["harvest", "--sim", "--world", "bush", "--look", "sun"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--look" in err and "--world row" in err
    with pytest.raises(ParameterError, match="look"):
        build_sim_rig(SimRigOptions(world="bush", look="sun"))


def test_demo_takes_the_row_and_a_look_for_the_row_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``softarm demo --world row --look L`` parses as ``harvest`` does; a look without
    the row, or one that does not exist, is one line naming ``--look`` and no output."""
    out = tmp_path / "demo"
    with pytest.raises(SystemExit) as exit_:
        main(["demo", "--world", "row", "--look", "noon", "--out", str(out)])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.count("\n") == 1 and "--look" in err
    assert main(["demo", "--world", "bush", "--look", "sun", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--look" in err and "--world row" in err
    assert not out.exists()


def test_culled_renders_keep_the_shadows_of_what_is_out_of_the_picture(row: Any) -> None:
    """A window (and the frame) leaves out the geoms it cannot see, but not those whose
    shadows fall into it: the same pixels as with nothing left out."""
    full = _world(RowLook.named("sun", SEED))
    try:
        full.renderer._cullable = full.renderer._cullable[:0]
        np.testing.assert_array_equal(
            row.renderer.render("c1_left").colour, full.renderer.render("c1_left").colour
        )
        for origin in ((20, 30), (150, 100), (250, 10)):
            np.testing.assert_array_equal(
                row.renderer.render_window("c1_left", origin, 64),
                full.renderer.render_window("c1_left", origin, 64),
            )
    finally:
        full.close()


def test_the_docs_print_the_looks_table() -> None:
    docs = (Path(__file__).resolve().parents[2] / "docs" / "perception.md").read_text()
    assert look_table() in docs, "docs/perception.md's looks table is stale"
