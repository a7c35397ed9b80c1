"""Body tracking from the depth, as the Kinect SDK does it (Shotton et al., CVPR 2011).

Per frame: the body pixels (body index 0 with a depth reading; every ``stride``-th pixel)
are classified into the parts of :mod:`.parts` by the forest of :mod:`.forest`; each part's
pixels are reprojected into camera space with their depth, weighted by ``P(part) * d^2``
(Shotton eq. 7: ``d^2`` makes the weight the pixel's surface area) over pixels with
``P(part) >= probability_threshold``, and the densest mean-shift mode (:mod:`.meanshift`)
is pushed from the surface along the viewing ray by the part's learned depth offset
(Shotton section 4, ``zeta_c``). Its confidence is the surface area (m^2) within one bandwidth
of the mode; a joint is Tracked above ``tracked_area_m2``, Inferred above
``inferred_area_m2``, NotTracked below (no proposal). Over a take, the joints go through the
SDK's smoothing (:mod:`.smoothing`) and onto the sensor's rig (:mod:`.rig_joints`), whose
orientations the sensor derives from those positions (:mod:`.orientations`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams.kinect.features import BACKGROUND_M, body_depth
from avatarsim.render_cams.kinect.forest import Forest, load_forest
from avatarsim.render_cams.kinect.meanshift import densest_mode
from avatarsim.render_cams.kinect.orientations import tracked_orientations
from avatarsim.render_cams.kinect.parts import N_PARTS
from avatarsim.render_cams.kinect.rig_joints import body17_dependencies, rig_joints_from_body17
from avatarsim.render_cams.kinect.sensors import DepthSensor, KinectError
from avatarsim.render_cams.kinect.skeleton import KinectSkeletonStream, TrackingState
from avatarsim.render_cams.kinect.smoothing import SmoothParameters, smooth_joints

MODELS = Path(__file__).with_name("models")
DEFAULT_MODEL = MODELS / "kinect-tracker.npz"
"""The shipped forest, made by ``avatarsim train kinect-tracker`` (its config and seed are in
the file's metadata)."""
SKELETON_SOURCE = "tracker"
"""``meta["skeleton"]`` of streams made by this tracker (the oracle is ``"oracle-noise"``)."""


SDK_SMOOTHING = SmoothParameters()
"""The SDK's default ``TransformSmoothParameters``."""


@dataclass(frozen=True, eq=False)
class BodyPartTracker:
    """The forest and the joint-proposal constants learned with it.

    Attributes:
        forest: part classifier over :data:`N_PARTS` classes (class ``k``: part ``k + 1``).
        push_m: ``(17,)`` metres from a part's surface mode to its joint along the ray.
        tracked_area_m2, inferred_area_m2: ``(17,)`` confidence thresholds.
        stride: classify every ``stride``-th pixel in both directions.
        bandwidth_m: mean-shift bandwidth.
        probability_threshold: pixels below it do not vote for a part.
        meta: training config, seed, data hash.
    """

    forest: Forest
    push_m: np.ndarray
    tracked_area_m2: np.ndarray
    inferred_area_m2: np.ndarray
    stride: int = 2
    bandwidth_m: float = 0.06
    probability_threshold: float = 0.2
    meta: dict[str, Any] = field(default_factory=dict)

    def classify(
        self, depth_mm: np.ndarray, body_index: np.ndarray, K: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Body pixels ``rows, cols (N,)``, their depth ``(N,)`` metres and part
        probabilities ``(N, 17)``."""
        depth = body_depth(depth_mm, body_index)
        mask = np.zeros(depth.shape, bool)
        mask[:: self.stride, :: self.stride] = True
        rows, cols = np.nonzero(mask & (depth < np.float32(BACKGROUND_M)))
        probs = self.forest.predict_proba(depth, K, rows, cols)
        return rows, cols, depth[rows, cols].astype(float), probs

    def propose(
        self, depth_mm: np.ndarray, body_index: np.ndarray, K: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(17, 3)`` joint proposals in OpenCV camera space (NaN: none) and ``(17,)``
        confidences (m^2 of part surface near the mode) of one frame."""
        rows, cols, d, probs = self.classify(depth_mm, body_index, K)
        joints = np.full((N_PARTS, 3), np.nan)
        conf = np.zeros(N_PARTS)
        if rows.size == 0:
            return joints, conf
        rays = np.stack(
            [(cols - K[0, 2]) / K[0, 0], (rows - K[1, 2]) / K[1, 1], np.ones_like(d)], 1
        )
        points = rays * d[:, None]
        area = d**2 * self.stride**2 / (K[0, 0] * K[1, 1])  # m^2 per classified pixel
        for k in range(N_PARTS):
            votes = probs[:, k] >= self.probability_threshold
            if not np.any(votes):
                continue
            mode, weight = densest_mode(
                points[votes], probs[votes, k] * area[votes], self.bandwidth_m
            )
            joints[k] = mode * (1.0 + self.push_m[k] / mode[2])
            conf[k] = weight
        return joints, conf

    def states(self, confidence: np.ndarray) -> np.ndarray:
        """``(..., 17)`` int8 :class:`TrackingState` of confidences ``(..., 17)``."""
        return np.where(
            confidence >= self.tracked_area_m2,
            TrackingState.TRACKED,
            np.where(
                confidence >= self.inferred_area_m2,
                TrackingState.INFERRED,
                TrackingState.NOT_TRACKED,
            ),
        ).astype(np.int8)

    def save(self, path: str | Path) -> Path:
        return self.forest.save(
            path,
            {
                **self.meta,
                "push_m": self.push_m.tolist(),
                "tracked_area_m2": self.tracked_area_m2.tolist(),
                "inferred_area_m2": self.inferred_area_m2.tolist(),
                "stride": self.stride,
                "bandwidth_m": self.bandwidth_m,
                "probability_threshold": self.probability_threshold,
            },
        )


def load_tracker(path: str | Path = DEFAULT_MODEL) -> BodyPartTracker:
    """The tracker stored at ``path`` (default: the shipped model)."""
    forest, meta = load_forest(path)
    try:
        return BodyPartTracker(
            forest,
            np.array(meta.pop("push_m"), float),
            np.array(meta.pop("tracked_area_m2"), float),
            np.array(meta.pop("inferred_area_m2"), float),
            int(meta.pop("stride")),
            float(meta.pop("bandwidth_m")),
            float(meta.pop("probability_threshold")),
            meta,
        )
    except KeyError as exc:
        raise KinectError(f"{path}: a forest without the tracker's constants ({exc})") from exc


def track(
    frames,
    sensor: DepthSensor,
    camera_to_world: np.ndarray,
    tracker: BodyPartTracker,
    smoothing: SmoothParameters | None = SDK_SMOOTHING,
) -> KinectSkeletonStream:
    """The skeleton stream the tracker reports on ``frames`` (an iterable of
    :class:`~render_cams.kinect.depth.DepthFrame`, at the sensor's rate) seen by ``sensor``
    at ``camera_to_world``: body17 joints proposed per frame, smoothed, placed on the rig."""
    K = sensor.K
    proposals = [tracker.propose(f.depth_mm, f.body_index, K) for f in frames]
    if not proposals:
        raise KinectError("no depth frames to track")
    cam = np.stack([p[0] for p in proposals])  # (T, 17, 3)
    b17_states = tracker.states(np.stack([p[1] for p in proposals]))
    rot, eye = camera_to_world[:3, :3], camera_to_world[:3, 3]
    world = cam @ rot.T + eye
    live = b17_states != TrackingState.NOT_TRACKED
    if smoothing is not None:
        world = smooth_joints(world, live, b17_states == TrackingState.INFERRED, smoothing)
    world = np.where(live[..., None], world, np.nan)
    rig = load_rig(sensor.rig)
    positions = rig_joints_from_body17(world, rig)
    orientations = tracked_orientations(positions, rig)
    states = np.stack([b17_states[:, deps].min(axis=1) for deps in body17_dependencies(rig)], 1)
    missing = ~np.all(np.isfinite(positions), axis=-1)
    states = np.where(missing, TrackingState.NOT_TRACKED, states).astype(np.int8)
    orientations = np.where(np.isfinite(orientations), orientations, [1.0, 0.0, 0.0, 0.0])
    n = len(proposals)
    return KinectSkeletonStream(
        rig=rig.name,
        joint_names=rig.skeleton.names,
        timestamps=np.arange(n) / sensor.rate_hz,
        positions=np.nan_to_num(positions),
        orientations=orientations,
        states=states,
        sensor_pose=np.asarray(camera_to_world, float),
        meta={
            "device": sensor.name,
            "rate_hz": sensor.rate_hz,
            "skeleton": SKELETON_SOURCE,
            "model": {k: tracker.meta.get(k) for k in ("config", "seed", "data_hash")},
            "smoothing": None if smoothing is None else smoothing.__dict__,
        },
    )
