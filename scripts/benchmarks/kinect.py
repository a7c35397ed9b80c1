"""Kinect simulation throughput next to the sensors' real 30 fps.

Rows: depth frames/s (render + noise + body index) for Kinect V2 (512 x 424) and Azure Kinect
NFOV (640 x 576), the body-part tracker's frames/s on those V2 depth frames (classify +
mean shift, no rendering), and the oracle skeleton's frames/s (joints, tracking state, noise)
on a 10 s clip.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models.generator import generate
from avatarsim.render_cams.kinect import default_sensor_pose, kinect_skeleton
from avatarsim.render_cams.kinect.depth import KinectDepthCamera
from avatarsim.render_cams.kinect.sensors import KINECT_RATE_HZ, get_sensor
from avatarsim.render_cams.kinect.tracker import load_tracker
from avatarsim.render_cams.scene import BodyScene
from avatarsim.scripts.benchmarks import BenchRow, best_of

_SENSOR_RATE = "sensor's own rate"


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    """Depth and skeleton rows; see the module docstring."""
    motion = generate("box", duration_s=2.0 if quick else 10.0, fps=30.0, seed=0)
    pose = default_sensor_pose(motion)
    frames = 10 if quick else 60
    rows = []
    captured = []
    with BodyScene(motion.skeleton) as scene:
        for device in ("kinect-v2", "azure-kinect"):
            camera = KinectDepthCamera(device, pose)
            rng = np.random.default_rng(0)

            def record(camera=camera, rng=rng) -> None:
                captured.clear()
                for t in range(frames):
                    scene.update(motion, t)
                    captured.append(camera.capture(scene, rng))

            seconds = best_of(record, 2 if quick else 3)
            rows.append(
                BenchRow(
                    f"kinect_depth[{device}]",
                    "frames/s",
                    frames / seconds,
                    KINECT_RATE_HZ,
                    _SENSOR_RATE,
                    f"{camera.sensor.width}x{camera.sensor.height}, render + noise + body index",
                )
            )
            if device == "kinect-v2":
                rows.append(_tracker_row(list(captured), quick))
    seconds = best_of(lambda: kinect_skeleton(motion, "azure-kinect", pose), 3)
    rows.append(
        BenchRow(
            "kinect_skeleton[azure-kinect]",
            "frames/s",
            motion.n_frames / seconds,
            KINECT_RATE_HZ,
            _SENSOR_RATE,
            f"{motion.n_frames} frames x 32 joints, occlusion + noise",
        )
    )
    return rows


def _tracker_row(depth_frames: list, quick: bool) -> BenchRow:
    """The shipped tracker's per-frame proposals on Kinect V2 depth frames."""
    tracker = load_tracker()
    K = get_sensor("kinect-v2").K

    def propose() -> None:
        for f in depth_frames:
            tracker.propose(f.depth_mm, f.body_index, K)

    seconds = best_of(propose, 2 if quick else 3)
    return BenchRow(
        "kinect_tracker[kinect-v2]",
        "frames/s",
        len(depth_frames) / seconds,
        KINECT_RATE_HZ,
        _SENSOR_RATE,
        f"{len(depth_frames)} depth frames, forest + mean shift (one core: taskset -c 0)",
    )
