"""Fisheye camera benchmarks: rendered frames/s per camera and keypoint projection rate.

Our targets: at least 25 fisheye frames/s per camera at 640x480 on one core and 200k
body17-frames/s of keypoint projection; the baseline column is the sensor's real 30 fps
(ControllerPose §4.1 cameras) and, for projection, ``cv2.fisheye.projectPoints``.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.fisheye.keypoints import project_joints, world_to_camera
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.render import FisheyeRenderer
from avatarsim.render_cams.fisheye.rig import camera_poses, controller_cameras
from avatarsim.render_cams.scene import BodyScene
from avatarsim.scripts.benchmarks import BenchRow, best_of

SENSOR_FPS = 30.0


def _render_rate(
    motion, poses, model, face_size, shading: str, antialias: bool, frames: int
) -> float:
    with BodyScene(motion.skeleton, shading=shading, antialias=antialias) as scene:
        renderer = FisheyeRenderer(scene, model, face_size)

        def render_all():
            for t in range(frames):
                scene.update(motion, t)
                renderer.render(poses[t, 0])

        render_all()  # warm-up: GL context, shader compilation
        return frames / best_of(render_all, repeat=2)


# (face_size, shading, antialias, label): the default path, the same with pyrender's 4x
# multisampling, and the first version (five full 90 deg faces at the fisheye's centre
# resolution, PBR shader, multisampled) for comparison.
RENDER_CONFIGS = (
    (None, "matte", False, "cropped resolution-matched faces, matte, single-sampled"),
    (None, "matte", True, "cropped resolution-matched faces, matte, 4x multisampled"),
    (496, "pbr", True, "five full 496 px faces, PBR, 4x multisampled (first version)"),
)


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    cv2.setNumThreads(1)  # "per camera on one core"
    motion = generate("box", duration_s=1.0, fps=30)
    poses = camera_poses(motion, controller_cameras())
    model = FisheyeModel.from_fov()
    frames = 5 if quick else 20
    rows = []
    for face_size, shading, antialias, label in RENDER_CONFIGS:
        rate = _render_rate(motion, poses, model, face_size, shading, antialias, frames)
        rows.append(
            BenchRow(
                f"fisheye render 640x480 ({label})", "frames/s", rate, SENSOR_FPS, "sensor 30 fps"
            )
        )
    n = 2_000 if quick else 50_000
    joints = np.resize(body17_positions(motion), (n, 17, 3))
    pose = np.resize(poses[:, 0], (n, 4, 4))
    ours = n / best_of(lambda: project_joints(model, pose, joints))
    w2c = world_to_camera(pose)
    cam = (np.einsum("tab,tjb->tja", w2c[:, :3, :3], joints) + w2c[:, None, :3, 3]).reshape(
        -1, 1, 3
    )
    opencv = n / best_of(
        lambda: cv2.fisheye.projectPoints(cam, np.zeros(3), np.zeros(3), model.K, model.D)
    )
    rows.append(
        BenchRow(
            "fisheye keypoint projection",
            "body17-frames/s",
            ours,
            opencv,
            "cv2.fisheye.projectPoints",
        )
    )
    return rows
