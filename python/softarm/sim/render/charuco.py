"""Rendered ChArUco views for camera calibration: a printed board (a textured quad) that
is moved in front of one camera or a stereo pair, drawn by MuJoCo with each camera's
OpenCV intrinsics and then its lens distortion, so that a calibration can be checked
against intrinsics and a baseline that are known exactly.

The board's pose is OpenCV's board frame (``cv2.aruco.CharucoBoard``'s object points:
origin at the outer corner of the top-left square, x along the columns, y along the
rows, z into the board) in the world frame, in which the cameras are placed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

from softarm.checks import FloatArray
from softarm.sim.render.distortion import Distorter
from softarm.sim.render.mjcf import CameraSpec, _camera, _mesh_name, _quad_mesh
from softarm.sim.render.renderer import HOW_TO_ENABLE, RenderUnavailableError, require_mujoco
from softarm.vision.camera_model import CameraModel
from softarm.vision.dictionaries import get_dictionary

__all__ = ["BoardSpec", "CharucoScene", "board_poses", "camera_spec"]

#: Texture pixels per board square: the corners stay sharp at the closest view.
PIXELS_PER_SQUARE = 96
#: The board in OpenCV's board frame (y down, z into the board) from the quad's frame
#: (y up, visible from +z): a half turn about x.
BOARD_FROM_QUAD = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class BoardSpec:
    """A ChArUco board: ``squares`` (columns, rows), the square and marker sides (m),
    the ArUco dictionary's name."""

    squares: tuple[int, int]
    square_length: float
    marker_length: float
    dictionary: str = "DICT_4X4_50"

    def board(self) -> Any:
        """The ``cv2.aruco.CharucoBoard``."""
        return cv2.aruco.CharucoBoard(
            self.squares, self.square_length, self.marker_length, get_dictionary(self.dictionary)
        )


def camera_spec(name: str, model: CameraModel, T_world_camera: FloatArray) -> CameraSpec:
    """The MuJoCo camera of ``model`` (square pixels: fx is used) at ``T_world_camera``."""
    assert model.image_size is not None, "a rendered camera needs its image size"
    k = model.matrix
    return CameraSpec(name, T_world_camera, model.image_size, float(k[0, 0]), (k[0, 2], k[1, 2]))


def _board_png(spec: BoardSpec) -> tuple[bytes, float, tuple[float, float]]:
    """The board's image padded white to a square, as PNG bytes; the square's side (m)
    and the board origin's offset from its centre in the board frame (m)."""
    cols, rows = spec.squares
    px = PIXELS_PER_SQUARE
    image = spec.board().generateImage((cols * px, rows * px), marginSize=0)
    side_px = (max(cols, rows) + 2) * px  # a square of white around the board
    top, left = (side_px - rows * px) // 2, (side_px - cols * px) // 2
    square = np.full((side_px, side_px), 255, np.uint8)
    square[top : top + rows * px, left : left + cols * px] = image
    ok, png = cv2.imencode(".png", cv2.cvtColor(square, cv2.COLOR_GRAY2BGR))
    metres = spec.square_length / px
    centre = ((side_px / 2 - left) * metres, (side_px / 2 - top) * metres)
    return png.tobytes() if ok else b"", side_px * metres, centre


def _scene_xml(spec: BoardSpec, cameras: Sequence[CameraSpec]) -> tuple[str, dict[str, bytes]]:
    png, side, _ = _board_png(spec)
    w = max(c.size[0] for c in cameras)
    h = max(c.size[1] for c in cameras)
    xml = (
        f'<mujoco model="charuco"><compiler angle="radian"/>'
        f'<visual><global offwidth="{w}" offheight="{h}"/><quality offsamples="4"/>'
        f'<headlight ambient="1 1 1" diffuse="0 0 0" specular="0 0 0"/>'
        f'<map znear="0.01" zfar="20"/></visual>'
        f'<asset><texture name="board" type="2d" file="board.png"/>'
        f'<material name="board" texture="board" specular="0" shininess="0"/>'
        f"{_quad_mesh(side)}</asset><worldbody>"
        f'<body name="board" mocap="true"><geom name="board" type="mesh" '
        f'mesh="{_mesh_name(side)}" material="board" contype="0" conaffinity="0"/></body>'
        f"{''.join(_camera(c) for c in cameras)}</worldbody></mujoco>"
    )
    return xml, {"board.png": png}


class CharucoScene:
    """The board ``spec`` and the ``cameras`` (name → (model, T_world_camera)); each
    :meth:`render` places the board and draws every camera, distortion applied.

    Raises:
        RenderUnavailableError: no MuJoCo or no offscreen OpenGL.
    """

    def __init__(self, spec: BoardSpec, cameras: dict[str, tuple[CameraModel, FloatArray]]) -> None:
        mujoco = require_mujoco()
        self._mj = mujoco
        self.spec = spec
        specs = [camera_spec(n, m, np.asarray(T, float)) for n, (m, T) in cameras.items()]
        xml, assets = _scene_xml(spec, specs)
        self.model = mujoco.MjModel.from_xml_string(xml, assets)
        self.data = mujoco.MjData(self.model)
        self._distort = {n: Distorter(m) for n, (m, _) in cameras.items()}
        self._sizes = {s.name: s.size for s in specs}
        self._renderers: dict[tuple[int, int], Any] = {}
        _, _, centre = _board_png(spec)
        self._T_board_quad = np.eye(4)
        self._T_board_quad[:3, :3] = BOARD_FROM_QUAD
        self._T_board_quad[:2, 3] = centre

    def render(self, T_world_board: FloatArray) -> dict[str, npt.NDArray[np.uint8]]:
        """Every camera's BGR image of the board at ``T_world_board`` (OpenCV's board
        frame, see the module docstring)."""
        T = np.asarray(T_world_board, dtype=np.float64) @ self._T_board_quad
        self.data.mocap_pos[0] = T[:3, 3]
        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        self.data.mocap_quat[0] = (w, x, y, z)
        self._mj.mj_kinematics(self.model, self.data)
        self._mj.mj_camlight(self.model, self.data)
        return {name: self._draw(name) for name in self._sizes}

    def close(self) -> None:
        """Free the OpenGL contexts."""
        for r in self._renderers.values():
            r.close()
        self._renderers.clear()

    def _draw(self, name: str) -> npt.NDArray[np.uint8]:
        r = self._renderer(self._sizes[name])
        r.update_scene(self.data, camera=name)
        bgr = np.ascontiguousarray(r.render()[..., ::-1])
        return self._distort[name].colour(bgr)

    def _renderer(self, size: tuple[int, int]) -> Any:
        if size not in self._renderers:
            try:
                self._renderers[size] = self._mj.Renderer(self.model, size[1], size[0])
            except (OSError, AttributeError, RuntimeError, self._mj.FatalError) as exc:  # no GL
                raise RenderUnavailableError(f"{HOW_TO_ENABLE} ({exc})") from exc
        return self._renderers[size]


def board_poses(
    spec: BoardSpec,
    n: int,
    seed: int,
    centre: tuple[float, float] = (0.0, 0.0),
    distance: tuple[float, float] = (0.5, 0.8),
) -> list[FloatArray]:
    """``n`` poses (OpenCV's board frame in the world) of the board ``spec`` whose middle
    lies within 20 cm (x) and 12 cm (y) of ``centre`` at ``distance`` along z, tilted up
    to 0.45 rad about x and y and 0.135 rad about z: the variety a calibration needs."""
    rng = np.random.default_rng(seed)
    middle = 0.5 * spec.square_length * np.array([*spec.squares, 0.0])
    poses = []
    for _ in range(n):
        rot = Rotation.from_rotvec(rng.uniform(-0.45, 0.45, 3) * [1, 1, 0.3]).as_matrix()
        at = [centre[0] + rng.uniform(-0.2, 0.2), centre[1] + rng.uniform(-0.12, 0.12),
              rng.uniform(*distance)]  # fmt: skip
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = rot, np.asarray(at) - rot @ middle
        poses.append(pose)
    return poses
