"""The end-effector marker cube: a pose from all visible markers jointly.

The markers are an ArUco ``Board`` (``cv2.aruco.Board``); ``matchImagePoints`` pairs the
detected corners with their cube-frame points, and the pose is the one that minimises the
reprojection error of all of them (``solvePnPRefineLM``). Starting points are both IPPE
solutions of every visible marker, so a single visible face yields its two ambiguous
poses; where they fit the image about equally well, the one nearer the ``previous`` pose
is kept (section II-C: a cube with four tags tracks the end effector).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError
from softarm.vision._checks import FloatArray, as_pose, positive
from softarm.vision.camera_model import CameraModel
from softarm.vision.detector import (
    Detection,
    MarkerDetector,
    marker_object_points,
    refined_pose,
    square_marker_poses,
)
from softarm.vision.dictionaries import check_marker_id
from softarm.vision.poses import (
    invert,
    rotation_angle,
    rvec_tvec_from_pose,
    transform_points,
)

# A candidate is "as good as the best" (planar ambiguity, then the previous pose decides)
# when its extra squared reprojection error is within what corner noise of std
# ``corner_sigma`` explains: N (rms² − best²) ≤ σ² χ²(6 dof, 99 %), N the matched corners
# (rms is per corner). 16.81 is the 99 % quantile of χ² with 6 degrees of freedom (a pose).
CHI2_6DOF_99 = 16.81
#: One marker's four corners fix its pose with 2 degrees of freedom to spare; corners a
#: leaf cuts or the view bends leave a residual that corner noise cannot explain: a
#: marker is consistent when 4 rms² ≤ σ² χ²(2 dof, 99 %), 9.21 that quantile.
CHI2_2DOF_99 = 9.21
DEFAULT_CORNER_SIGMA_PX = 0.05
#: A marker seen more than this far (degrees) from face-on is left out of the pose when one
#: within it is seen: foreshortened by cos θ, its corners' error grows as 1 / cos θ
#: along the compressed axis (twice the face-on error at 60°), and in the joint fit it
#: pulls the pose along the line of sight, the axis a marker's size measures worst.
DEFAULT_MAX_VIEW_ANGLE_DEG = 60.0
#: A printed tag's square (its quiet zone around the marker) is this many times the
#: marker's side: the paper's 80 mm tags on the cube's 100 mm faces.
FACE_PER_MARKER = 1.25


@dataclass(frozen=True)
class CubePose:
    """A cube pose estimate: ``T_camera_cube``, RMS reprojection error (px), markers used,
    and whether they are :meth:`MarkerCube.consistent` (False: no marker's corners were,
    and the pose is the least bent marker's, possibly centimetres off)."""

    T_camera_cube: FloatArray
    rms: float
    marker_ids: tuple[int, ...]
    consistent: bool = True


class MarkerCube:
    """A rigid set of square markers: ``markers`` maps id → (4, 4) pose of the marker in
    the cube frame (ArUco marker convention: z out of the face); all share ``marker_length``
    (m) and ``dictionary``. ``corner_sigma`` (px) is the expected corner noise, which sets
    how close in reprojection error two solutions must be to count as ambiguous;
    markers seen more than ``max_view_angle`` (degrees) from face-on are left out of the
    pose while one within it is seen (:data:`DEFAULT_MAX_VIEW_ANGLE_DEG`)."""

    def __init__(
        self,
        markers: Mapping[int, npt.ArrayLike],
        marker_length: float,
        dictionary: str = "DICT_4X4_50",
        corner_sigma: float = DEFAULT_CORNER_SIGMA_PX,
        max_view_angle: float = DEFAULT_MAX_VIEW_ANGLE_DEG,
    ) -> None:
        if not markers:
            raise ParameterError("markers must name at least one marker, got none")
        self.marker_length = positive(marker_length, "marker_length")
        self.dictionary = dictionary
        self.corner_sigma = positive(corner_sigma, "corner_sigma")
        self.max_view_angle = positive(max_view_angle, "max_view_angle")
        if self.max_view_angle > 90.0:
            raise ParameterError(f"max_view_angle must be at most 90 degrees, got {max_view_angle}")
        self.markers: dict[int, FloatArray] = {
            check_marker_id(dictionary, k): as_pose(v, f"markers[{k}]") for k, v in markers.items()
        }
        corners = marker_object_points(self.marker_length)
        ids = sorted(self.markers)
        self._object_points = {i: transform_points(self.markers[i], corners) for i in ids}
        self.board = cv2.aruco.Board(
            [self._object_points[i].astype(np.float32) for i in ids],
            cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary)),
            np.array(ids, dtype=np.int32),
        )
        self.detector = MarkerDetector(dictionary)

    @classmethod
    def standard(
        cls,
        marker_length: float = 0.08,
        cube_size: float | None = None,
        ids: tuple[int, int, int, int] = (0, 1, 2, 3),
        dictionary: str = "DICT_4X4_50",
    ) -> MarkerCube:
        """The paper's cube: four markers on the four side faces (normals +x, +y, -x, -y
        of the cube frame, in the order of ``ids``), each marker's y axis along the cube's
        +z. ``cube_size`` (edge, m) defaults to 1.25 × ``marker_length`` (80 mm tags on a
        100 mm cube). The cube frame is at the cube's centre."""
        length = positive(marker_length, "marker_length")
        size = FACE_PER_MARKER * length if cube_size is None else positive(cube_size, "cube_size")
        if size < length:
            raise ParameterError(f"cube_size must be >= marker_length, got {size} < {length}")
        markers = {}
        for k, marker_id in enumerate(ids):
            a = k * np.pi / 2
            n = np.array([np.cos(a), np.sin(a), 0.0])  # face normal = marker z
            y = np.array([0.0, 0.0, 1.0])
            pose = np.eye(4)
            pose[:3, :3] = np.column_stack([np.cross(y, n), y, n])
            pose[:3, 3] = 0.5 * size * n
            markers[marker_id] = pose
        return cls(markers, length, dictionary)

    def object_points(self, marker_id: int) -> FloatArray:
        """(4, 3) corners of marker ``marker_id`` in the cube frame, detection order."""
        return self._object_points[marker_id].copy()

    def estimate_pose(
        self,
        image: npt.NDArray[Any] | None,
        camera: CameraModel,
        previous: npt.ArrayLike | None = None,
    ) -> FloatArray | None:
        """``T_camera_cube`` (4, 4) from ``image``, or None when no cube marker is seen.

        ``previous`` (a recent ``T_camera_cube``) resolves the single-face ambiguity.
        """
        est = self.estimate(self.detector.detect(image, camera), camera, previous)
        return None if est is None else est.T_camera_cube

    def estimate(
        self,
        detections: list[Detection],
        camera: CameraModel,
        previous: npt.ArrayLike | None = None,
    ) -> CubePose | None:
        """Like :meth:`estimate_pose` from existing detections, with fit details: the
        pose from the cube's markers whose corners are consistent on their own
        (:meth:`consistent`; when none is, the least bent one's, flagged), then, if some
        are seen too obliquely, again from the frontal ones alone (the first pose
        breaking their planar ambiguity)."""
        prev = None if previous is None else as_pose(previous, "previous", tol=1e-4)
        own = self._own_fits(detections, camera)
        mine = self._consistent_of(own)
        trusted = bool(mine)
        if not trusted and own:  # the least bent: one marker's error, not a mix of several
            mine = [min(own, key=lambda fit: fit[1][0].rms if fit[1] else np.inf)[0]]
        pick = self._pick(self._candidates_of(mine, own, camera), prev)
        if pick is not None and len(pick.marker_ids) > 1:
            frontal = self.frontal_ids(pick.T_camera_cube, pick.marker_ids)
            if len(frontal) < len(pick.marker_ids):
                kept = [d for d in mine if d.marker_id in frontal]
                pick = self._pick(self.candidates(kept, camera), pick.T_camera_cube) or pick
        return None if pick is None else replace(pick, consistent=trusted)

    def consistent(self, detections: list[Detection], camera: CameraModel) -> list[Detection]:
        """The cube's markers among ``detections`` whose four corners fit a pose of their
        own within the corner noise (see :data:`CHI2_2DOF_99`). A marker whose code
        still reads but whose corners are wrong (a leaf over one, an edge the
        refinement could not measure) would move the pose by centimetres."""
        return self._consistent_of(self._own_fits(detections, camera))

    def _consistent_of(self, own: list[tuple[Detection, list[CubePose]]]) -> list[Detection]:
        limit = self.corner_sigma * float(np.sqrt(CHI2_2DOF_99 / 4.0))
        return [d for d, cands in own if cands and cands[0].rms <= limit]

    def _candidates_of(
        self,
        mine: list[Detection],
        own: list[tuple[Detection, list[CubePose]]],
        camera: CameraModel,
    ) -> list[CubePose]:
        """The candidates of the markers ``mine``: a lone marker's are its own fit's."""
        if len(mine) == 1:
            return next(cands for d, cands in own if d is mine[0])
        return self.candidates(mine, camera)

    def _own_fits(
        self, detections: list[Detection], camera: CameraModel
    ) -> list[tuple[Detection, list[CubePose]]]:
        """Each of the cube's markers among ``detections`` with the candidates of its
        four corners alone, best first."""
        mine = [d for d in detections if d.marker_id in self.markers]
        return [(d, self.candidates([d], camera)) for d in mine]

    def view_angles(self, T_camera_cube: FloatArray, ids: tuple[int, ...]) -> FloatArray:
        """Degrees between each marker ``ids``'s normal and the line of sight to its centre
        when the cube is at ``T_camera_cube`` (0 face-on, 90 edge-on); empty for no ids.

        Raises:
            PoseError: ``T_camera_cube`` is no pose.
            ParameterError: ``ids`` names no marker of this cube.
        """
        T = as_pose(T_camera_cube, "T_camera_cube", tol=1e-4)
        unknown = [i for i in ids if i not in self.markers]
        if unknown:
            raise ParameterError(
                f"ids: {unknown} are no markers of this cube (it has {sorted(self.markers)})"
            )
        if not ids:
            return np.zeros(0)
        poses = np.stack([T @ self.markers[i] for i in ids])
        normals, centres = poses[:, :3, 2], poses[:, :3, 3]
        cos = -np.einsum("ij,ij->i", normals, centres) / np.linalg.norm(centres, axis=1)
        return np.asarray(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))

    def frontal_ids(self, T_camera_cube: FloatArray, ids: tuple[int, ...]) -> tuple[int, ...]:
        """The ``ids`` seen within ``max_view_angle`` of face-on, or all of them when none
        is (the cube seen from near its open end: then the joint fit is the better)."""
        angles = self.view_angles(T_camera_cube, ids)
        kept = tuple(i for i, a in zip(ids, angles, strict=True) if a <= self.max_view_angle)
        return kept or ids

    def _pick(self, cands: list[CubePose], prev: FloatArray | None) -> CubePose | None:
        """The best candidate, or among those as good (corner noise), the one nearest
        ``prev``; None when there are none."""
        if not cands:
            return None
        if prev is None:
            return cands[0]
        n = round(len(cands[0].marker_ids) * 4)
        limit = self.corner_sigma**2 * CHI2_6DOF_99 / n
        ok = [c for c in cands if c.rms**2 - cands[0].rms ** 2 <= limit]
        return min(ok, key=lambda c: rotation_angle(c.T_camera_cube, prev))

    def candidates(self, detections: list[Detection], camera: CameraModel) -> list[CubePose]:
        """Every local optimum found: each IPPE solution of each visible cube marker,
        refined by LM over all matched corners; lowest RMS first ([] if none)."""
        mine = [d for d in detections if d.marker_id in self.markers]
        if not mine:
            return []
        corners = [d.corners.astype(np.float32).reshape(1, 4, 2) for d in mine]
        ids = np.array([d.marker_id for d in mine], dtype=np.int32)
        obj_pts, _ = self.board.matchImagePoints(corners, ids)
        if obj_pts is None or len(obj_pts) < 4:
            return []
        # matchImagePoints hands back float32; the refinement below works in float64
        # from the original (float64) corners, in the same marker order.
        obj = np.asarray(obj_pts, dtype=np.float64).reshape(-1, 3)
        img = np.concatenate([d.corners for d in mine]).reshape(-1, 2)
        used = tuple(int(i) for i in ids)
        out = []
        for det in mine:
            # IPPE's two solutions seed the joint fit unrefined (refined alone they can
            # fall into one, and the joint fit needs both).
            seeds = square_marker_poses(det.corners, camera, self.marker_length, refine=False)
            for sol in seeds:
                start = sol.T_camera_marker @ invert(self.markers[det.marker_id])
                pose, rms = self._refine(start, obj, img, camera)
                out.append(CubePose(pose, rms, used))
        out.sort(key=lambda c: c.rms)
        return out

    @staticmethod
    def _refine(
        start: FloatArray, obj: FloatArray, img: FloatArray, camera: CameraModel
    ) -> tuple[FloatArray, float]:
        """Levenberg–Marquardt over all matched corners from ``start``; (pose, RMS px)."""
        fit = refined_pose(*rvec_tvec_from_pose(start), obj, img, camera)
        return fit.T_camera_marker, fit.rms


class CubeTracker:
    """Tracks one :class:`MarkerCube` in one camera, feeding each estimate back as the
    ``previous`` pose of the next (so a lone visible face keeps its correct solution)."""

    def __init__(self, cube: MarkerCube, camera: CameraModel) -> None:
        self.cube, self.camera = cube, camera
        self.last: FloatArray | None = None

    def update(self, image: npt.NDArray[Any] | None) -> FloatArray | None:
        """``T_camera_cube`` for this frame, or None (the last pose is kept for the next)."""
        pose = self.cube.estimate_pose(image, self.camera, self.last)
        if pose is not None:
            self.last = pose
        return pose

    def reset(self) -> None:
        """Forget the previous pose."""
        self.last = None
