"""Training the body-part tracker on the testbed's own rendered depth (Shotton section 2).

:class:`TrackerTrainingConfig` (a TOML file, e.g. ``models/kinect-tracker.toml``) names
built-in subjects and activities, frames per clip and sensor yaws about the performer;
:func:`render_training_frames` renders them with the sensor's depth noise, part labels and
true body17 joints; :func:`train_tracker` samples body pixels, fits scikit-learn's
``ExtraTreesClassifier`` (randomised thresholds, as Shotton's forest, section 3.2) on the
depth features, and learns the proposal constants (push-back depth and confidence
thresholds) on the same frames. Deterministic for a config and seed.
"""

from __future__ import annotations

import hashlib
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.config import ConfigError, load_toml, setting
from avatarsim.avatar_models.generator import ACTIVITIES, generate, sample_subject
from avatarsim.avatar_models.memory import require_memory
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.kinect.depth import KinectDepthCamera
from avatarsim.render_cams.kinect.features import DepthFeatures, body_depth
from avatarsim.render_cams.kinect.forest import from_sklearn
from avatarsim.render_cams.kinect.parts import N_PARTS
from avatarsim.render_cams.kinect.placement import default_sensor_pose, orbit, performer_target
from avatarsim.render_cams.kinect.sensors import SENSORS, KinectError, get_sensor
from avatarsim.render_cams.kinect.tracker import BodyPartTracker, load_tracker
from avatarsim.render_cams.scene import BodyScene


@dataclass(frozen=True)
class TrackerTrainingConfig:
    """What the tracker is trained on and how (see ``models/kinect-tracker.toml``)."""

    sensor: str = "kinect-v2"
    seed: int = setting(0, ge=0)
    subjects: int = setting(6, ge=1)
    activities: tuple[str, ...] = setting(
        ("walk", "wave", "squat", "box", "lunge", "kick", "balance"), min_items=1
    )
    seconds: float = setting(2.0, gt=0.0)
    frames_per_clip: int = setting(3, ge=1)
    yaw_deg: tuple[float, ...] = setting((-45.0, 0.0, 45.0), min_items=1)
    pixels_per_frame: int = setting(400, ge=1)
    features: int = setting(200, ge=1)
    max_offset_m: float = setting(0.5, gt=0.0)
    trees: int = setting(3, ge=1)
    max_depth: int = setting(18, ge=1)
    min_samples_leaf: int = setting(20, ge=1)

    def memory_bytes(self) -> float:
        """Bytes training holds: every rendered frame's depth (uint16) and part labels
        (uint8) at the sensor's size, and the float32 feature matrix of the sampled pixels
        (``pixels_per_frame x features`` a frame)."""
        sensor = get_sensor(self.sensor)
        n = float(self.subjects) * len(self.activities) * self.frames_per_clip * len(self.yaw_deg)
        return n * (
            3.0 * sensor.width * sensor.height + 4.0 * self.pixels_per_frame * self.features
        )


def load_training_config(path: str | Path) -> TrackerTrainingConfig:
    """The config in TOML file ``path`` (:mod:`avatar_models.config`).

    Raises:
        ConfigError: unreadable file, unknown keys, bad values, or more memory than the
        machine has (:func:`avatar_models.memory.require_memory`).
    """
    config = load_toml(TrackerTrainingConfig, path)
    if config.sensor not in SENSORS:
        raise ConfigError(
            f"{path}: sensor must be one of {', '.join(SENSORS)}, got {config.sensor!r}"
        )
    unknown = sorted(set(config.activities) - set(ACTIVITIES))
    if unknown:
        raise ConfigError(f"{path}: activities must be some of {ACTIVITIES}, got {unknown}")
    require_memory(config.memory_bytes(), f"{path}: the tracker's training frames")
    return config


def check_model_output(path: str | Path) -> None:
    """Before any work: ``path`` may receive a model (an ``.npz`` name, and no file there
    but one this training wrote, which it replaces).

    Raises:
        KinectError: another name or someone else's file.
    """
    path = Path(path)
    if path.suffix != ".npz":
        raise KinectError(f"{path}: a tracker model is an .npz file; name it *.npz")
    if not path.exists() or path.is_dir():
        return  # a folder is refused by the caller's output checks
    try:
        made_by = load_tracker(path).meta.get("made_by")
    except KinectError:
        made_by = None
    if made_by != MADE_BY:
        raise KinectError(
            f"{path} exists and is not a model this command wrote; choose another --out or "
            "move it away"
        )


def render_views(motion, sensor, poses, rng, noise="default"):
    """Depth frames of every frame of ``motion`` from each pose in ``poses``; yields
    ``(frame index, pose, DepthFrame)``."""
    camera_of = [KinectDepthCamera(sensor, p, noise) for p in poses]
    with BodyScene(motion.skeleton) as scene:
        for t in range(motion.n_frames):
            scene.update(motion, t)
            for pose, camera in zip(poses, camera_of, strict=True):
                yield t, pose, camera.capture(scene, rng)


def render_training_frames(
    config: TrackerTrainingConfig,
    subject_offset: int = 0,
    progress: Callable[[int, int], None] | None = None,
):
    """``(frames, poses, joints)``: DepthFrames, their ``(4, 4)`` sensor poses and true
    body17 joints ``(17, 3)`` world, for every subject, activity, frame and yaw of
    ``config`` (subjects ``subject_offset ...``: held-out sets use an offset).
    ``progress(clips done, clips)`` is called after each clip."""
    sensor = get_sensor(config.sensor)
    rng = np.random.default_rng([config.seed, subject_offset])
    frames, poses, joints = [], [], []
    per_clip = config.frames_per_clip * len(config.yaw_deg)
    n_clips = config.subjects * len(config.activities)
    for s in range(subject_offset, subject_offset + config.subjects):
        subject = sample_subject(np.random.default_rng([config.seed, s]))
        for a, activity in enumerate(config.activities):
            motion = generate(activity, subject, config.seconds, sensor.rate_hz, seed=s * 97 + a)
            picks = np.linspace(0, motion.n_frames - 1, config.frames_per_clip).round()
            clip = motion[picks.astype(int)]
            front = default_sensor_pose(clip, sensor)
            centre = performer_target(clip)
            views = [orbit(front, centre, np.radians(y)) for y in config.yaw_deg]
            b17 = body17_positions(clip)
            for t, pose, frame in render_views(clip, sensor, views, rng):
                frames.append(frame)
                poses.append(pose)
                joints.append(b17[t])
            if progress is not None:
                progress(len(frames) // per_clip, n_clips)
    return frames, poses, joints


def data_hash(frames) -> str:
    """SHA-256 (first 16 hex digits) of the frames' depth and part labels."""
    digest = hashlib.sha256()
    for f in frames:
        digest.update(f.depth_mm.tobytes())
        digest.update(f.parts.tobytes())
    return digest.hexdigest()[:16]


def train_tracker(config: TrackerTrainingConfig, frames=None) -> BodyPartTracker:
    """The tracker trained on ``frames`` (default: :func:`render_training_frames`)."""
    from sklearn.ensemble import ExtraTreesClassifier

    frames, poses, joints = frames or render_training_frames(config)
    sensor = get_sensor(config.sensor)
    K = sensor.K
    rng = np.random.default_rng(config.seed)
    features = DepthFeatures.sample(config.features, config.max_offset_m, rng)
    X, y = [], []
    all_features = np.arange(len(features))
    for frame in frames:
        rows, cols = np.nonzero(frame.parts > 0)
        if rows.size == 0:
            continue
        pick = rng.choice(rows.size, min(config.pixels_per_frame, rows.size), replace=False)
        depth = body_depth(frame.depth_mm, frame.body_index)
        X.append(features.evaluate(depth, K, rows[pick], cols[pick], all_features[None]))
        y.append(frame.parts[rows[pick], cols[pick]].astype(int) - 1)
    model = ExtraTreesClassifier(
        n_estimators=config.trees,
        max_depth=config.max_depth,
        min_samples_leaf=config.min_samples_leaf,
        max_features="sqrt",
        random_state=config.seed,
        n_jobs=1,
    )
    model.fit(np.concatenate(X).astype(np.float32), np.concatenate(y))
    forest = from_sklearn(model, features, N_PARTS)
    zeros = np.zeros(N_PARTS)
    draft = BodyPartTracker(forest, zeros, zeros, zeros)
    push, area = _proposal_statistics(draft, frames, poses, joints, K)
    meta = {
        "config": asdict(config),
        "seed": config.seed,
        "data_hash": data_hash(frames),
        "frames": len(frames),
        "classifier": "sklearn.ensemble.ExtraTreesClassifier",
        "made_by": MADE_BY,
    }
    return BodyPartTracker(
        forest, push, TRACKED_SHARE * area, INFERRED_SHARE * area, draft.stride, meta=meta
    )


MADE_BY = "avatarsim train kinect-tracker"
"""``meta["made_by"]`` of every model :func:`train_tracker` makes: the command replaces a
model file only when it carries this mark."""
TRACKED_SHARE = 0.25
"""A joint is Tracked when its part's confidence reaches this share of the training median."""
INFERRED_SHARE = 0.05
"""... and Inferred from this share on; below it, no proposal (NotTracked)."""


def _proposal_statistics(tracker, frames, poses, joints, K) -> tuple[np.ndarray, np.ndarray]:
    """Per part: the median depth from surface mode to true joint (``zeta_c``) and the
    median confidence of the proposals, over the training frames."""
    pushes, areas = [], []
    for frame, pose, b17 in zip(frames, poses, joints, strict=True):
        modes, conf = tracker.propose(frame.depth_mm, frame.body_index, K)
        truth_z = ((b17 - pose[:3, 3]) @ pose[:3, :3])[:, 2]
        pushes.append(truth_z - modes[:, 2])
        areas.append(np.where(conf > 0, conf, np.nan))
    with warnings.catch_warnings():  # a part never proposed in the set: 0 (no push, area)
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nan_to_num(np.nanmedian(pushes, 0)), np.nan_to_num(np.nanmedian(areas, 0))
