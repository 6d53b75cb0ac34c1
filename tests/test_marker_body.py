"""The marker bodies (softarm.vision.marker_body): their tags a rigid, buildable set, the
frustum's pose from a synthetic picture at every approach angle, the bodies drawn alike
in the rendered world's scene, and the config and command-line spellings."""

from __future__ import annotations

import json
import re
import types
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm.commands import _marker_bodies
from softarm.config import parse_config
from softarm.errors import ConfigError
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import cube_scene_markers
from softarm.vision import CameraModel, MarkerCube
from softarm.vision.marker_body import (
    MARKER_BODIES,
    SIMULATED_BODY,
    body_markers,
    check_marker_body,
    marker_body,
    overlapping_panels,
    panel_corners,
)

DEFAULT = resources.files("softarm.data").joinpath("blackberry.toml").read_text("utf-8")


@pytest.mark.parametrize("name", MARKER_BODIES)
def test_tags_are_a_rigid_set_facing_outwards_without_overlap(name: str) -> None:
    body = marker_body(name, 0.08)
    assert sorted(body.markers) == [0, 1, 2, 3]
    centre = panel_corners(body).reshape(-1, 3).mean(axis=0)
    for pose in body.markers.values():
        R = pose[:3, :3]
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        assert R[:, 2] @ (pose[:3, 3] - centre) > 0.0  # the tag faces out of the body
        assert R[:, 1] @ [0.0, 0.0, 1.0] > 0.0  # upright: its y towards the body's front
    assert overlapping_panels(body) == []


def test_the_cube_body_is_the_paper_cube() -> None:
    cube, paper = marker_body("cube", 0.06), MarkerCube.standard(0.06)
    for i, pose in paper.markers.items():
        np.testing.assert_allclose(cube.markers[i], pose, atol=1e-15)


def test_the_frustum_leans_its_tags_back_towards_the_arm() -> None:
    for pose in body_markers("frustum", 0.08).values():
        normal = pose[:3, 2]
        assert np.degrees(np.arcsin(-normal[2])) == pytest.approx(40.0)


def test_overlap_check_finds_crossing_tags() -> None:
    # Two tags crossing at right angles through each other's middle.
    a, b = np.eye(4), np.eye(4)
    b[:3, :3] = Rotation.from_euler("y", 90, degrees=True).as_matrix()
    assert overlapping_panels(MarkerCube({0: a, 1: b}, 0.08)) == [(0, 1)]


def _facing(phi: float, azimuth: float, distance: float = 0.5) -> np.ndarray:
    """``T_camera_body`` with the camera ``phi`` degrees off the body's back axis (-z) at
    ``azimuth`` about it."""
    p, a = np.radians(phi), np.radians(azimuth)
    to_camera = np.array([np.sin(p) * np.cos(a), np.sin(p) * np.sin(a), -np.cos(p)])
    R, _ = Rotation.align_vectors([[0.0, 0.0, -1.0]], [to_camera])
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R.as_matrix(), [0.02, -0.01, distance]
    return T


@pytest.fixture(scope="module")
def small_camera() -> tuple[CameraModel, SyntheticCamera]:
    # C1's pixel scale (f 900 px at 1 m) at half the distance and half the focal length.
    model = CameraModel.ideal(450.0, 640, 480, [-0.05, 0.01, 0.0, 0.0, 0.0])
    return model, SyntheticCamera(model, 640, 480, noise_std=2.0, supersample=2, seed=5)


@pytest.mark.parametrize("phi", [15, 30, 45, 60, 75])
def test_frustum_pose_within_half_a_millimetre_at_every_approach(
    small_camera: tuple[CameraModel, SyntheticCamera], phi: float
) -> None:
    model, camera = small_camera
    body = marker_body("frustum", 0.08)
    for azimuth in (-90.0, -135.0, 180.0):
        T = _facing(phi, azimuth)
        image = camera.render(cube_scene_markers(body.markers, 0.08, body.dictionary, T))
        est = body.estimate_pose(image, model)
        assert est is not None, (phi, azimuth)
        assert np.linalg.norm(est[:3, 3] - T[:3, 3]) < 0.5e-3, (phi, azimuth)


def test_the_cube_is_not_found_from_near_its_open_end(
    small_camera: tuple[CameraModel, SyntheticCamera],
) -> None:
    model, camera = small_camera
    cube = marker_body("cube", 0.08)
    T = _facing(15.0, -90.0)
    image = camera.render(cube_scene_markers(cube.markers, 0.08, cube.dictionary, T))
    assert cube.estimate_pose(image, model) is None


@pytest.mark.parametrize("name", MARKER_BODIES)
def test_the_rendered_world_draws_the_body_tracked(name: str) -> None:
    from softarm.sim.render import mjcf

    spec = types.SimpleNamespace(
        n_sections=1, hand_cameras=[], cube_marker=0.08, marker_body=name, cube_ids=(0, 1, 2, 3)
    )
    xml = mjcf._arm(spec)  # type: ignore[arg-type]
    drawn = re.findall(r'name="arm_cubeface(\d)"[^>]*pos="([^"]+)" quat="([^"]+)"', xml)
    assert len(drawn) == 4
    body = marker_body(name, 0.08)
    for marker_id, pos, quat in drawn:
        w, x, y, z = (float(v) for v in quat.split())
        pose = body.markers[int(marker_id)]
        np.testing.assert_allclose([float(v) for v in pos.split()], pose[:3, 3], atol=1e-5)
        R = Rotation.from_quat([x, y, z, w]).as_matrix()
        np.testing.assert_allclose(R, pose[:3, :3], atol=1e-5)


def _with_calibration(lines: str) -> str:
    return DEFAULT.replace("[calibration]", f"[calibration]\n{lines}", 1)


def test_config_selects_the_body_and_keeps_the_cube_by_default() -> None:
    assert parse_config(DEFAULT, source="t.toml").calibration.marker_body == "cube"
    text = _with_calibration('marker_body = "frustum"\nmarker_length = 0.06')
    cal = parse_config(text, source="t.toml").calibration
    assert (cal.marker_body, cal.marker_length) == ("frustum", 0.06)


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ('marker_body = "sphere"', "t.toml: calibration.marker_body must be one of cube, frustum"),
        ("marker_body = 3", "calibration.marker_body must be one of cube, frustum, got 3"),
        ("marker_length = 0", "calibration.marker_length must be > 0"),
        ("marker_length = 'big'", "calibration.marker_length must be a finite number"),
    ],
)
def test_bad_body_config_is_one_line_naming_the_key(line: str, message: str) -> None:
    with pytest.raises(ConfigError, match=re.escape(message)) as info:
        parse_config(_with_calibration(line), source="t.toml")
    assert "\n" not in str(info.value)


def test_unknown_body_name_names_the_key() -> None:
    with pytest.raises(ConfigError, match="marker_body must be one of cube, frustum, got 'x'"):
        check_marker_body("x")


def test_the_command_line_knows_the_same_bodies() -> None:
    assert _marker_bodies.MARKER_BODIES == MARKER_BODIES


def test_the_harvest_takes_a_marker_body_in_the_simulator_only(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from softarm.cli import main
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    with pytest.raises(SystemExit) as exit_:
        main(["harvest", "--sim", "--marker-body", "ball"])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.count("\n") == 1 and "--marker-body" in err
    config = resources.files("softarm.data").joinpath("blackberry.toml")
    assert main(["harvest", "--config", str(config), "--marker-body", "frustum"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--marker-body" in err and "[calibration]" in err
    with pytest.raises(ConfigError, match="marker_body must be one of"):
        build_sim_rig(SimRigOptions(marker_body="ball"))


def test_tracking_errors_binned_by_approach_angle() -> None:
    from softarm.experiments.cube_tracking import ANGLE_BINS, Pose, by_angle

    poses = [
        Pose(0.1, 35.0, 1.0, True),
        Pose(0.3, 45.0, 1.0, True),
        Pose(None, 48.0, 0.5, False),  # not found: counted, not scored
        Pose(2.0, 65.0, 1.0, False),
        Pose(9.0, 90.0, 1.0, True),  # the last bin holds its upper edge
    ]
    rows = by_angle(poses)
    assert [r["angle_deg"] for r in rows] == ["0-40", "40-50", "50-60", "60-70", "70-90"]
    assert len(rows) == len(ANGLE_BINS) - 1
    assert [(r["poses"], r["found"]) for r in rows] == [(1, 1), (2, 1), (0, 0), (1, 1), (1, 1)]
    assert rows[1]["median_mm"] == pytest.approx(0.3)
    assert np.isnan(rows[2]["median_mm"]) and rows[4]["p95_mm"] == pytest.approx(9.0)


@pytest.mark.parametrize(
    ("flag", "body"), [([], SIMULATED_BODY), (["--marker-body", "cube"], "cube")]
)
def test_the_simulator_carries_the_frustum_unless_told_and_logs_its_body(
    tmp_path: Path, flag: list[str], body: str
) -> None:
    # The simulator's default is the frustum; the hardware's stays the cube (above).
    from softarm.cli import main

    log = tmp_path / "run.jsonl"
    args = ["harvest", "--sim", "--berries", "1", "--seed", "90031", "--log", str(log), "-q"]
    assert main([*args, *flag]) in (0, 1)  # 1: the berry not harvested
    header = json.loads(log.read_text().splitlines()[0])
    assert SIMULATED_BODY == "frustum" and header["marker_body"] == body
