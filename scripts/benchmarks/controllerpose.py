"""ControllerPose latency per stage on CPU, next to the paper's (§4.4: 297 ms end to end,
7.2 FPS; 2D pose estimation ~128 ms, Unity with its IK ~17 ms).

Rows, per camera frame (ms): keypoints (projected, the dataset's channel; the paper's
compositing + 2D pose estimation, 63 + 128 ms, render images and run OpenPose instead), the
§4.3 features, the network (one frame, batch of 1: a live system's case; and per frame in a
batch of 128), FK, and the post-processing IK per 90 Hz tick; then the whole pipeline's
frames/s against 7.2 FPS. An untrained network of the default size: the weights do not
change the time. One torch thread.
"""

from __future__ import annotations

import numpy as np
import torch

from avatar_models.body17_angles import angles_from_positions
from avatar_models.generator import generate
from avatar_models.rigs import body17_positions
from render_cams.vr import HEADSET_AND_CONTROLLERS, VRSetup
from scripts.benchmarks import BenchRow, best_of
from scripts.controllerpose.recording import keypoint_recording
from sim.humanoid import humanoid_for
from synthesis.base import FrameBatch, on_clock
from synthesis.controllerpose.checkpoint import untrained
from synthesis.controllerpose.examples import VRStream, frame_features
from synthesis.controllerpose.fk import forward_kinematics
from synthesis.controllerpose.synthesizer import ControllerPose

PAPER_MS = {"pose_estimation": 128.0, "compositing": 63.0, "unity_ik": 17.0, "total": 297.0}
PAPER_FPS = 7.2


def run(quick: bool = False) -> list[BenchRow]:
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
            "controllerpose_keypoints",
            "ms/frame",
            1000 * per_frame["keypoints"],
            PAPER_MS["compositing"] + PAPER_MS["pose_estimation"],
            "paper compositing + 2D pose (§4.4)",
            "projected, no images rendered",
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
    ]
    return rows
