"""One-time checkerboard calibration of a fisheye camera (ControllerPose §4.2), simulated.

ControllerPose corrects each camera with OpenCV's fisheye model after "a one-time
checkerboard calibration procedure". Here the checkerboard views are rendered analytically
through a known :class:`FisheyeModel` (the truth), the corners are found with
``cv2.findChessboardCornersSB`` and ``cv2.fisheye.calibrate`` recovers K and D, which are
compared with the truth.

Why analytic rendering rather than the pyrender scene: every fisheye pixel's ray is exact
(:meth:`FisheyeModel.unproject`), so intersecting it with the board plane and sampling the
checker pattern images the board exactly through the true model, with no rasteriser or
cube-map resampling in between; ``SUPERSAMPLE`` x ``SUPERSAMPLE`` rays per pixel give the
anti-aliased edges a real sensor integrates, which sub-pixel corner detection relies on. It is
also independent of the renderer, so the calibration checks the model, not the renderer.
The rays are pose-independent: unprojected once, each view is one plane intersection.

Board: 9 x 6 inner corners of 25 mm squares (OpenCV's sample pattern size) on a white margin
of one square, in front of a grey background.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import CalibrationError
from avatarsim.render_cams.fisheye.model import FisheyeModel

PATTERN = (9, 6)  # inner corners (columns, rows), OpenCV's calibration sample
SQUARE_M = 0.025
SUPERSAMPLE = 3  # rays per pixel along each axis
BACKGROUND = 0.35  # grey level around the board
DISTANCE_M = (0.18, 0.40)  # board centre distance: close enough for a 150 deg lens
OFF_AXIS_DEG = 60.0  # largest angle of the board centre from the optical axis
TILT_DEG = 40.0  # largest tilt of the board away from facing the camera
EDGE_MARGIN_PX = 6.0  # the whole board (with its white margin) stays this far inside
CALIBRATION_FLAGS = cv2.CALIB_RECOMPUTE_EXTRINSIC | cv2.CALIB_CHECK_COND | cv2.CALIB_FIX_SKEW
DETECTOR_FLAGS = cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_EXHAUSTIVE | cv2.CALIB_CB_ACCURACY


def board_corners() -> np.ndarray:
    """``(N, 3)`` inner corners in the board frame (metres, z = 0), row-major as OpenCV
    orders a detected pattern of ``PATTERN`` columns."""
    cols, rows = PATTERN
    j, i = np.mgrid[1 : rows + 1, 1 : cols + 1]
    return np.stack([i.ravel(), j.ravel(), np.zeros(i.size)], axis=1) * SQUARE_M


def board_outline() -> np.ndarray:
    """``(4, 3)`` outer corners of the board including its white margin (board frame)."""
    w, h = (PATTERN[0] + 3) * SQUARE_M, (PATTERN[1] + 3) * SQUARE_M
    return np.array([[0, 0, 0], [w, 0, 0], [w, h, 0], [0, h, 0]], float) - SQUARE_M


def supersampled_rays(model: FisheyeModel) -> np.ndarray:
    """``(H, W, S*S, 3)`` float32 unit rays (camera frame) through ``S x S`` sub-pixel
    positions of every pixel (pixel centres at integer coordinates); NaN outside the circle."""
    s = SUPERSAMPLE
    offsets = (np.arange(s) + 0.5) / s - 0.5
    v, u = np.mgrid[0 : model.height, 0 : model.width].astype(np.float64)
    du, dv = np.meshgrid(offsets, offsets)
    uv = np.stack([u[..., None] + du.ravel(), v[..., None] + dv.ravel()], axis=-1)
    return model.unproject(uv).astype(np.float32)


def render_board(rays: np.ndarray, board_to_cam: np.ndarray) -> np.ndarray:
    """``(H, W)`` uint8 image of the checkerboard at ``board_to_cam`` ``(4, 4)`` seen along
    ``rays`` ``(H, W, S, 3)`` (:func:`supersampled_rays`): each ray meets the board plane,
    takes the pattern's value there (black/white squares, white margin, grey elsewhere) and
    the ``S`` values of a pixel are averaged."""
    rot = board_to_cam[:3, :3].astype(np.float32)
    origin = board_to_cam[:3, 3].astype(np.float32)
    normal = rot[:, 2]
    along = rays @ normal  # (H, W, S)
    with np.errstate(invalid="ignore", divide="ignore"):
        reach = float(origin @ normal) / along
    hit = np.isfinite(reach) & (reach > 0)
    # Board coordinates (in squares) of the hit points: R^T (reach * ray - origin).
    local = (rays * reach[..., None] - origin) @ rot / SQUARE_M
    bx, by = np.nan_to_num(local[..., 0], nan=-1e6), np.nan_to_num(local[..., 1], nan=-1e6)
    cols, rows = PATTERN
    in_squares = (bx >= 0) & (bx < cols + 1) & (by >= 0) & (by < rows + 1)
    in_board = (bx >= -1) & (bx < cols + 2) & (by >= -1) & (by < rows + 2)
    white = (np.floor(bx) + np.floor(by)) % 2 == 1
    value = np.where(in_board & hit, np.where(in_squares & ~white, 0.0, 1.0), BACKGROUND)
    return np.round(255.0 * value.mean(axis=-1)).astype(np.uint8)


def random_board_pose(model: FisheyeModel, rng: np.random.Generator) -> np.ndarray:
    """``(4, 4)`` board-to-camera pose, drawn until the whole board is inside the image:
    centre up to ``OFF_AXIS_DEG`` off axis at ``DISTANCE_M``, roughly facing the camera
    (tilt up to ``TILT_DEG``, any roll), so the corners sample centre and periphery."""
    centre = 0.5 * (board_outline()[0] + board_outline()[2])
    while True:
        off = np.radians(OFF_AXIS_DEG) * np.sqrt(rng.uniform())
        azimuth = rng.uniform(0.0, 2.0 * np.pi)
        direction = np.array(
            [np.sin(off) * np.cos(azimuth), np.sin(off) * np.sin(azimuth), np.cos(off)]
        )
        position = rng.uniform(*DISTANCE_M) * direction
        # Face the camera (board z along the view ray), then tilt and roll at random.
        facing = Rotation.align_vectors([direction], [[0.0, 0.0, 1.0]])[0]
        tilt_axis = rng.normal(size=3)
        tilt_axis[2] = 0.0
        tilt = Rotation.from_rotvec(
            np.radians(TILT_DEG) * rng.uniform() * tilt_axis / np.linalg.norm(tilt_axis)
        )
        roll = Rotation.from_rotvec([0.0, 0.0, rng.uniform(0.0, 2.0 * np.pi)])
        rot = (facing * tilt * roll).as_matrix()
        pose = np.eye(4)
        pose[:3, :3] = rot
        pose[:3, 3] = position - rot @ centre
        outline_cam = board_outline() @ rot.T + pose[:3, 3]
        uv, _ = model.project(outline_cam)
        inside = (
            np.all(outline_cam[:, 2] > 0)
            & np.all(uv >= EDGE_MARGIN_PX)
            & np.all(uv[:, 0] <= model.width - 1 - EDGE_MARGIN_PX)
            & np.all(uv[:, 1] <= model.height - 1 - EDGE_MARGIN_PX)
        )
        if inside:
            return pose


def detect_corners(
    image: np.ndarray, expected_uv: np.ndarray, tolerance_px: float = 3.0
) -> np.ndarray | None:
    """``(N, 2)`` sub-pixel inner corners of ``image`` in :func:`board_corners` order, or
    None when the pattern is not found.

    ``cv2.findChessboardCornersSB`` returns the grid either way round (a 9 x 6 board looks the
    same turned by 180 deg); ``expected_uv`` ``(N, 2)`` (the corners' rough positions)
    picks the orientation, as a printed board's asymmetric marker would. A detection further
    than ``tolerance_px`` from every orientation is rejected as a false match."""
    found, corners = cv2.findChessboardCornersSB(image, PATTERN, flags=DETECTOR_FLAGS)
    if not found:
        return None
    corners = corners.reshape(-1, 2).astype(np.float64)
    candidates = (corners, corners[::-1])
    errors = [np.max(np.linalg.norm(c - expected_uv, axis=1)) for c in candidates]
    best = int(np.argmin(errors))
    return candidates[best] if errors[best] < tolerance_px else None


@dataclass(frozen=True)
class CalibrationResult:
    """Recovered intrinsics against the truth.

    Attributes:
        truth: the model the views were rendered with.
        K: ``(3, 3)`` recovered camera matrix; D: ``(4,)`` recovered k1..k4.
        rms_px: RMS reprojection error reported by ``cv2.fisheye.calibrate``.
        n_views: views used; n_tried: views rendered (undetected ones are dropped).
        seed: seed of the board poses.
    """

    truth: FisheyeModel
    K: np.ndarray
    D: np.ndarray
    rms_px: float
    n_views: int
    n_tried: int
    seed: int
    errors: dict = field(init=False)

    def __post_init__(self) -> None:
        tk = self.truth.K
        px = {
            "fx": self.K[0, 0] - tk[0, 0],
            "fy": self.K[1, 1] - tk[1, 1],
            "cx": self.K[0, 2] - tk[0, 2],
            "cy": self.K[1, 2] - tk[1, 2],
        }
        errors = {f"{k}_px": float(v) for k, v in px.items()}
        errors["fx_rel"] = float(px["fx"] / tk[0, 0])
        errors["fy_rel"] = float(px["fy"] / tk[1, 1])
        errors["D_abs"] = np.abs(self.D - self.truth.D).tolist()
        errors["rms_px"] = float(self.rms_px)
        object.__setattr__(self, "errors", errors)

    @property
    def model(self) -> FisheyeModel:
        """The recovered camera as a :class:`FisheyeModel`."""
        return FisheyeModel(self.K, self.D, self.truth.width, self.truth.height)

    def as_dict(self) -> dict:
        """JSON-ready: truth and recovered K, D, the errors, views and seed."""
        return {
            "truth": self.truth.as_dict(),
            "K": self.K.tolist(),
            "D": self.D.tolist(),
            "errors": self.errors,
            "n_views": self.n_views,
            "n_tried": self.n_tried,
            "seed": self.seed,
        }


def calibrate_fisheye(
    model_truth: FisheyeModel, n_views: int = 20, seed: int = 0, max_tries: int | None = None
) -> CalibrationResult:
    """Render ``n_views`` detected checkerboard views through ``model_truth`` at random
    poses (``seed``) and calibrate with ``cv2.fisheye.calibrate`` (recompute extrinsics,
    fix skew, check conditioning), starting from OpenCV's own initial guess.

    Raises:
        CalibrationError: fewer than ``n_views`` boards found in ``max_tries`` (default
            ``4 n_views``) renders, or OpenCV's optimisation failed.
    """
    if n_views < 3:
        raise CalibrationError(f"fisheye calibration needs at least 3 views, got {n_views}")
    rng = np.random.default_rng(seed)
    rays = supersampled_rays(model_truth)
    object_points, image_points = [], []
    tries, limit = 0, 4 * n_views if max_tries is None else max_tries
    while len(image_points) < n_views and tries < limit:
        tries += 1
        pose = random_board_pose(model_truth, rng)
        corners_cam = board_corners() @ pose[:3, :3].T + pose[:3, 3]
        expected, _ = model_truth.project(corners_cam)
        corners = detect_corners(render_board(rays, pose), expected)
        if corners is not None:
            object_points.append(board_corners().reshape(1, -1, 3))
            image_points.append(corners.reshape(1, -1, 2))
    if len(image_points) < n_views:
        raise CalibrationError(
            f"found the checkerboard in {len(image_points)} of {tries} views, needed {n_views}"
        )
    criteria = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12)
    try:
        rms, K, D, _, _ = cv2.fisheye.calibrate(
            object_points,
            image_points,
            (model_truth.width, model_truth.height),
            np.zeros((3, 3)),
            np.zeros(4),
            flags=CALIBRATION_FLAGS,
            criteria=criteria,
        )
    except cv2.error as exc:
        raise CalibrationError(f"cv2.fisheye.calibrate failed: {exc}".splitlines()[0]) from exc
    return CalibrationResult(
        model_truth, K, np.asarray(D, float).reshape(4), float(rms), n_views, tries, seed
    )
