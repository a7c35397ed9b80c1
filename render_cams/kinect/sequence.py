"""A Kinect recording (:class:`~render_cams.kinect.device.KinectRecording`) on disk.

Layout of ``out_dir``::

    depth/000000.png        uint16 depth in millimetres (0 = no reading)
    body_index/000000.png   uint8, 0 = body, 255 = no body
    parts/000000.png        uint8 ground-truth body parts (:mod:`.parts`), 0 = none
    skeleton/000000.json    joints (world and camera space), orientations, tracking states
    preview.mp4             colour-mapped depth with the skeleton drawn on it
    recording.json          device, K, image size, sensor pose, seed, frame count, fps

:func:`read_kinect_skeleton` reads the skeleton stream back (MoveBox plays recorded takes).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from avatarsim.render_cams.kinect.depth import colourise, write_png
from avatarsim.render_cams.kinect.device import KinectRecording
from avatarsim.render_cams.kinect.sensors import DepthSensor, KinectError
from avatarsim.render_cams.kinect.skeleton import KinectSkeletonStream, TrackingState

_STATE_BGR = {
    TrackingState.TRACKED: (80, 220, 80),
    TrackingState.INFERRED: (0, 215, 255),
}


def write_kinect_recording(recording: KinectRecording, out_dir: str | Path) -> dict[str, Any]:
    """Write ``recording`` into ``out_dir`` (created); return the ``recording.json`` contents
    (its record plus the preview's file name)."""
    sensor, skeleton = recording.sensor, recording.skeleton
    out = Path(out_dir)
    for sub in ("depth", "body_index", "parts", "skeleton"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    video_path = out / "preview.mp4"
    video = cv2.VideoWriter(
        str(video_path),
        cv2.VideoWriter_fourcc(*"mp4v"),
        sensor.rate_hz,
        (sensor.width, sensor.height),
    )
    for t, frame in enumerate(recording.frames):  # rendered one by one: constant memory
        name = f"{t:06d}"
        write_png(frame.depth_mm, out / "depth" / f"{name}.png")
        write_png(frame.body_index, out / "body_index" / f"{name}.png")
        write_png(frame.parts, out / "parts" / f"{name}.png")
        (out / "skeleton" / f"{name}.json").write_text(skeleton.to_json(t))
        video.write(_preview(frame.depth_mm, skeleton, t, sensor))
    video.release()
    record = {**recording.record, "preview": video_path.name}
    (out / "recording.json").write_text(json.dumps(record, indent=1, sort_keys=True))
    return record


def _preview(
    depth_mm: np.ndarray, skeleton: KinectSkeletonStream, t: int, sensor: DepthSensor
) -> np.ndarray:
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


def read_kinect_skeleton(folder: str | Path) -> KinectSkeletonStream:
    """The skeleton stream of a recording folder written by :func:`write_kinect_recording`
    (``skeleton/*.json`` and ``recording.json``): NotTracked joints come back with NaN
    positions and identity orientations, as the SDK reports no data for them.

    Raises:
        KinectError: no such folder, no skeleton frame, or a malformed frame.
    """
    folder = Path(folder)
    paths = sorted((folder / "skeleton").glob("*.json"))
    if not paths:
        raise KinectError(f"{folder}: no Kinect skeleton frames (skeleton/*.json)")
    try:
        record = json.loads((folder / "recording.json").read_text())
        frames = [json.loads(p.read_text()) for p in paths]
        names = tuple(j["name"] for j in frames[0]["joints"])
        states = np.array(
            [[TrackingState[j["tracking_state"]] for j in f["joints"]] for f in frames], np.int8
        )
        positions = np.array(
            [[j["position_world_m"] or [np.nan] * 3 for j in f["joints"]] for f in frames], float
        )
        orientations = np.array(
            [[j["orientation_wxyz"] or [1.0, 0, 0, 0] for j in f["joints"]] for f in frames], float
        )
        timestamps = np.array([f["timestamp_s"] for f in frames], float)
        stream = KinectSkeletonStream(
            rig=frames[0]["rig"],
            joint_names=names,
            timestamps=timestamps,
            positions=positions,
            orientations=orientations,
            states=states,
            sensor_pose=np.array(record["camera_to_world"], float),
            meta={
                "device": record.get("device"),
                "rate_hz": record.get("fps"),
                "source": str(folder),
            },
        )
    except (OSError, ValueError, KeyError, TypeError, IndexError) as exc:
        raise KinectError(
            f"{folder}: not a Kinect recording ({type(exc).__name__}: {exc})"
        ) from exc
    if positions.shape != (len(frames), len(names), 3):
        raise KinectError(f"{folder}: frames disagree on their joints")
    return stream
