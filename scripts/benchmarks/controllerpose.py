"""ControllerPose latency per stage on CPU, next to the paper's (§4.4: 297 ms end to end,
7.2 FPS; 2D pose estimation ~128 ms, Unity with its IK ~17 ms).

Rows, per camera frame (ms): compositing (§4.2: per controller, its two 640 x 480 RGB
camera images undistorted, projected onto the cylinder and gradient-blended by
:meth:`~render_cams.fisheye.stitch.StitchParams.stitch`, maps calibrated once, plus the
torso-normal view's perspective warp of the composite, §4.3; against the paper's 63 ms),
keypoints (projected, the dataset's channel: no 2D pose network runs here, the paper's
OpenPose took 128 ms), the §4.3 features, the network (one frame, batch of 1: a live
system's case; and per frame in a batch of 128), FK, and the post-processing IK per 90 Hz
tick; then the whole pipeline's frames/s against 7.2 FPS, and the stages' sum per camera
frame against the paper's 297 ms motion-to-photon latency (which also holds ~75 ms of video
transmission and the display; ours is compute only). An untrained network of the default
size: the weights do not change the time. One torch thread.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import torch

from avatarsim.avatar_models.body17_angles import angles_from_positions
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.rig import CONTROLLERS, controller_cameras
from avatarsim.render_cams.fisheye.stitch import stitch_params
from avatarsim.render_cams.fisheye.torso_view import torso_view
from avatarsim.render_cams.vr import HEADSET_AND_CONTROLLERS, VRSetup
from avatarsim.scripts.benchmarks import BenchRow, best_of
from avatarsim.scripts.controllerpose.recording import keypoint_recording
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.synthesis.base import FrameBatch, on_clock
from avatarsim.synthesis.controllerpose.checkpoint import untrained
from avatarsim.synthesis.controllerpose.examples import VRStream, frame_features
from avatarsim.synthesis.controllerpose.fk import forward_kinematics
from avatarsim.synthesis.controllerpose.synthesizer import ControllerPose

PAPER_MS = {"pose_estimation": 128.0, "compositing": 63.0, "unity_ik": 17.0, "total": 297.0}
PAPER_FPS = 7.2
VIEW_SLOTS = (0, 2)  # the left and right composite views' keypoints (:mod:`...features`)


def compositing_s(uv: np.ndarray, conf: np.ndarray, repeat: int) -> float:
    """Seconds per camera frame to composite both controllers' images and warp each composite
    to its torso-normal view (module docstring), the views' transforms from the composite
    keypoints ``uv (T, 4, 17, 2)``, ``conf (T, 4, 17)`` of a frame that gives them."""
    model = FisheyeModel.from_fov()
    params = [stitch_params(model, controller_cameras((c,))) for c in CONTROLLERS]
    images = [np.full((model.height, model.width, 3), 128, np.uint8)] * 2
    views = torso_view(uv[:, VIEW_SLOTS], conf[:, VIEW_SLOTS] > 0)
    frame = int(np.argmax(views.valid.all(-1)))  # identity transforms cost the same

    def composite_and_warp() -> None:
        for k, p in enumerate(params):
            composite = p.stitch(images)
            size = (composite.shape[1], composite.shape[0])
            cv2.warpPerspective(composite, views.H[frame, k], size)

    return best_of(composite_and_warp, repeat)


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    """Per-stage rows; see the module docstring."""
    torch.set_num_threads(1)
    motion = generate("walk", duration_s=1.0 if quick else 3.0, fps=30.0, seed=0)
    humanoid = humanoid_for(motion)
    height = float(motion.meta["subject"]["height_m"])
    keypoints_s = best_of(lambda: keypoint_recording(humanoid, 0), 2)
    recording = keypoint_recording(humanoid, 0)
    frames = len(recording.time)
    stream = on_clock(VRSetup(devices=HEADSET_AND_CONTROLLERS).sample(humanoid.motion, seed=0))
    vr = VRStream(
        stream.timestamps, stream.positions, stream.quaternions, stream.valid, stream.device_names
    )
    features_s = best_of(
        lambda: frame_features(recording.uv, recording.conf, recording.time, vr), 3
    )
    _, lengths = angles_from_positions(body17_positions(humanoid.motion))
    checkpoint = untrained(lengths.mean(0) / height)
    model = checkpoint.model()
    features, _, _ = frame_features(recording.uv, recording.conf, recording.time, vr)
    inputs = [torch.from_numpy(a) for a in (features.skeletons, features.found, features.vr)]
    with torch.no_grad():
        one_s = best_of(lambda: [model(*(x[i : i + 1] for x in inputs)) for i in range(frames)])
        batch_s = best_of(lambda: model(*(x[:128] for x in inputs)), 5)
        angles = model(*inputs)
        lengths = torch.from_numpy(checkpoint.template_lengths.astype(np.float32) * height)
        fk_s = best_of(
            lambda: [forward_kinematics(angles[i : i + 1], lengths) for i in range(frames)]
        )
    synth = ControllerPose(checkpoint, recording, humanoid.body.skeleton, height)
    batch = FrameBatch.of_stream(stream)

    def pipeline() -> None:
        synth.reset()
        synth.advance(batch)

    ticks = batch.size
    pipeline_s = best_of(pipeline, 1 if quick else 2)
    per_frame = {
        "compositing": compositing_s(recording.uv, recording.conf, 2 if quick else 5),
        "keypoints": keypoints_s / frames,
        "features": features_s / frames,
        "network": one_s / frames,
        "fk": fk_s / frames,
    }
    ik_ms = (
        1000
        * (pipeline_s - (per_frame["features"] + per_frame["network"] + per_frame["fk"]) * frames)
        / ticks
    )
    rows = [
        BenchRow(
            "controllerpose_compositing",
            "ms/frame",
            1000 * per_frame["compositing"],
            PAPER_MS["compositing"],
            "paper unwarping + compositing (§4.4)",
            "2 controllers: stitch 2 x 640x480 RGB + torso-view warp",
        ),
        BenchRow(
            "controllerpose_keypoints",
            "ms/frame",
            1000 * per_frame["keypoints"],
            PAPER_MS["pose_estimation"],
            "paper 2D pose estimation, OpenPose (§4.4)",
            "projected + detector error model, no pose network",
        ),
        BenchRow(
            "controllerpose_features",
            "ms/frame",
            1000 * per_frame["features"],
            note="136 directions + 17 confidences x 4 skeletons, 15 VR",
        ),
        BenchRow(
            "controllerpose_network",
            "ms/frame",
            1000 * per_frame["network"],
            1000 * batch_s / min(128, frames),
            "per frame in a batch of 128",
            "batch of 1 (live), CPU, 1 thread",
        ),
        BenchRow(
            "controllerpose_fk", "ms/frame", 1000 * per_frame["fk"], note="torch FK, batch of 1"
        ),
        BenchRow(
            "controllerpose_ik",
            "ms/tick",
            ik_ms,
            PAPER_MS["unity_ik"],
            "paper Unity + FinalIK (§4.4)",
            "humanoid IK + foot grounding per 90 Hz tick (pipeline minus the stages above)",
        ),
        BenchRow(
            "controllerpose_pipeline",
            "frames/s",
            frames / pipeline_s,
            PAPER_FPS,
            "paper full pipeline 7.2 FPS (§4.4)",
            "features + network + FK + IK per camera frame (3 IK ticks each), keypoints apart",
        ),
        BenchRow(
            "controllerpose_compute_per_frame",
            "ms/frame",
            1000 * (per_frame["compositing"] + per_frame["keypoints"] + pipeline_s / frames),
            PAPER_MS["total"],
            "paper motion-to-photon latency (§4.4)",
            "compositing + keypoints + pipeline; no OpenPose, no video link, no display",
        ),
    ]
    return rows
