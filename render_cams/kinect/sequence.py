"""A Kinect recording on disk: depth PNGs, body-index PNGs, skeleton JSON and a preview video.

Layout of ``out_dir``::

    depth/000000.png        uint16 depth in millimetres (0 = no reading)
    body_index/000000.png   uint8, 0 = body, 255 = no body
    skeleton/000000.json    joints (world and camera space), orientations, tracking states
    preview.mp4             colour-mapped depth with the skeleton drawn on it
    recording.json          device, K, image size, sensor pose, seed, frame count, fps
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from avatar_models import Motion
from avatar_models.body import BodyDescription
from render_cams.device import motion_at_rate, resolve_seed
from render_cams.kinect.depth import KinectDepthCamera, colourise, write_png
from render_cams.kinect.placement import (
    DEFAULT_HEIGHT_M,
    default_sensor_pose,
    performer_distance,
)
from render_cams.kinect.sensors import KinectError, get_sensor
from render_cams.kinect.skeleton import KinectSkeletonStream, TrackingState, kinect_skeleton
from render_cams.scene import BodyScene, body_for_motion

_STATE_BGR = {
    TrackingState.TRACKED: (80, 220, 80),
    TrackingState.INFERRED: (0, 215, 255),
}


def render_kinect_sequence(
    motion: Motion,
    out_dir: str | Path,
    device: str = "kinect-v2",
    seed: int | np.random.Generator = 0,
    sensor_pose: np.ndarray | None = None,
    max_frames: int | None = None,
    depth_noise: Any = "default",
    skeleton_noise: Any = "default",
    body: BodyDescription | None = None,
    sensor_height_m: float = DEFAULT_HEIGHT_M,
) -> dict[str, Any]:
    """Record ``motion`` with a simulated Kinect at 30 Hz and write it to ``out_dir``.

    Args:
        motion: any motion whose rig has a body17 map.
        out_dir: output folder (created).
        device: a name of :data:`~render_cams.kinect.sensors.SENSORS`.
        seed: one seed for depth and skeleton noise; recorded in ``recording.json``.
        sensor_pose: ``(4, 4)`` camera-to-world (OpenCV axes); default: set up for this take
            by :func:`~render_cams.kinect.placement.default_sensor_pose` (in front of the
            performer, the whole take in range and view where the range allows), at
            ``sensor_height_m`` above the floor.
        max_frames: record at most this many frames (from the start).
        depth_noise, skeleton_noise: ``"default"``, a model, or ``None`` for clean output.
        body: the humanoid built once for ``motion`` (``motion`` on its skeleton); default:
            a body built from ``motion``'s skeleton.

    Returns:
        The ``recording.json`` contents (``frames``, ``fps``, paths...).
    """
    sensor = get_sensor(device)
    if max_frames is not None and max_frames < 1:
        raise KinectError(f"max_frames must be at least 1, got {max_frames}")
    sampled = motion_at_rate(motion, sensor.rate_hz)
    if max_frames is not None:
        sampled = sampled[: int(max_frames)]
    body = body_for_motion(sampled, body)
    placed = sensor_pose is None
    pose = (
        default_sensor_pose(sampled, sensor, sensor_height_m)
        if placed
        else np.asarray(sensor_pose, float)
    )
    used_seed = resolve_seed(seed)
    skeleton = kinect_skeleton(sampled, sensor, pose, used_seed, skeleton_noise, body)
    camera = KinectDepthCamera(sensor, pose, depth_noise)
    rng = np.random.default_rng([used_seed, 1])  # the skeleton noise uses used_seed itself
    out = Path(out_dir)
    for sub in ("depth", "body_index", "skeleton"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    video_path = out / "preview.mp4"
    video = cv2.VideoWriter(
        str(video_path),
        cv2.VideoWriter_fourcc(*"mp4v"),
        sensor.rate_hz,
        (sensor.width, sensor.height),
    )
    with BodyScene(body) as scene:
        for t in range(sampled.n_frames):
            scene.update(sampled, t)
            frame = camera.capture(scene, rng)
            name = f"{t:06d}"
            write_png(frame.depth_mm, out / "depth" / f"{name}.png")
            write_png(frame.body_index, out / "body_index" / f"{name}.png")
            (out / "skeleton" / f"{name}.json").write_text(skeleton.to_json(t))
            video.write(_preview(frame.depth_mm, skeleton, t, sensor))
    video.release()
    record = {
        "device": sensor.name,
        "frames": sampled.n_frames,
        "fps": sensor.rate_hz,
        "width": sensor.width,
        "height": sensor.height,
        "K": sensor.K.tolist(),
        "D": [0.0] * 5,
        "range_m": list(sensor.range_m),
        "camera_to_world": pose.tolist(),
        "sensor_placement": "auto" if placed else "given",
        "performer_depth_m_median": round(float(np.median(performer_distance(pose, sampled))), 4),
        "tracked_fraction": round(float(np.mean(skeleton.states == TrackingState.TRACKED)), 4),
        "not_tracked_frames": int(np.sum(np.all(skeleton.states == TrackingState.NOT_TRACKED, 1))),
        "world_to_camera": np.linalg.inv(pose).tolist(),
        "rig": skeleton.rig,
        "joint_names": list(skeleton.joint_names),
        "seed": used_seed,
        "depth_unit": "mm",
        "body_index_none": 255,
        "preview": video_path.name,
    }
    (out / "recording.json").write_text(json.dumps(record, indent=1, sort_keys=True))
    return record


def _preview(depth_mm: np.ndarray, skeleton: KinectSkeletonStream, t: int, sensor) -> np.ndarray:
    """``(H, W, 3)`` BGR: colour-mapped depth with joints (green tracked, amber inferred)."""
    image = colourise(depth_mm, sensor.range_m)
    rot, eye = skeleton.sensor_pose[:3, :3], skeleton.sensor_pose[:3, 3]
    cam = (skeleton.positions[t] - eye) @ rot
    K = sensor.K
    for point, state in zip(cam, skeleton.states[t], strict=True):
        if state == TrackingState.NOT_TRACKED or point[2] <= 0:
            continue
        u = int(round(K[0, 0] * point[0] / point[2] + K[0, 2]))
        v = int(round(K[1, 1] * point[1] / point[2] + K[1, 2]))
        cv2.circle(image, (u, v), 3, _STATE_BGR[TrackingState(int(state))], -1)
    return image
