"""ControllerPose as a :class:`~synthesis.base.Synthesizer` (§4.3, Fig. 6): the controller
cameras' 2D keypoints plus the VR stream in, a full body on the humanoid out.

Per camera frame (the keypoints' clock, :class:`KeypointRecording`): the features of
:mod:`.features` with the latest usable VR samples at or before that frame, the network's 43
angles, FK with the template bone lengths at the user's height, and the keypoints placed in
the world: turned to the headset's heading, the head keypoint where the headset says the
head is (its nominal attachment taken off). Per 90 Hz tick the newest camera frame at or
before the tick is used (the method never reads a future frame); ticks before the first
usable frame stand in the rest pose, frames without a skeleton hold the last keypoints
("awaits better frames").

Post-processing (§4.3: FinalIK in Unity): IK on the humanoid to the 17 keypoints (mink,
:class:`~avatar_models.body.ik.HumanoidIK`, one warm-started solve per tick), and foot
grounding: a foot keypoint within :data:`GROUND_SNAP_M` of its standing height is anchored
there (held where it landed); any foot above it is raised. Each foot is decided on its own,
so both may leave the floor (the paper's prototype allowed one raised foot at a time).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from threadpoolctl import threadpool_limits

from avatarsim.avatar_models import Motion, Skeleton, quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.body.ik import HumanoidIK, IKSettings, humanoid_model, motion_from_qpos
from avatarsim.avatar_models.body17 import BODY17, INDEX
from avatarsim.avatar_models.measure import standing_height
from avatarsim.render_cams import TrackingStream
from avatarsim.render_cams.vr import HEADSET_AND_CONTROLLERS, nominal_attachment
from avatarsim.synthesis.base import DEFAULT_RATE_HZ, FrameBatch, Poses, SynthesisError, Synthesizer
from avatarsim.synthesis.controllerpose.checkpoint import FILE, Checkpoint, load
from avatarsim.synthesis.controllerpose.examples import VRStream, frame_features
from avatarsim.synthesis.controllerpose.features import (
    SKELETON_SLOTS,
    heading_matrix,
    latest_sample,
)
from avatarsim.synthesis.controllerpose.fk import forward_kinematics

MODEL_ENV = "AVATARSIM_CONTROLLERPOSE_MODEL"
DEFAULT_MODEL = Path("out/controllerpose")
GROUND_SNAP_M = 0.05  # ours: §4.3 says "near the floor" without a number
FEET = (INDEX["l_ankle"], INDEX["l_foot"]), (INDEX["r_ankle"], INDEX["r_foot"])
IK_ITERATIONS_PER_TICK = 4
HEAD_COST = 10.0  # the head follows the headset, the best-known point


@dataclass(frozen=True)
class KeypointRecording:
    """The controller cameras' 2D keypoints over time.

    Attributes:
        time: ``(Tc,)`` seconds, increasing, on the VR stream's clock.
        uv: ``(Tc, 4, 17, 2)`` pixels (slots as :mod:`.features` describes).
        conf: ``(Tc, 4, 17)`` in [0, 1]; 0 where a joint was not detected.
    """

    time: np.ndarray
    uv: np.ndarray
    conf: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.time)
        if self.uv.shape != (n, SKELETON_SLOTS, 17, 2) or self.conf.shape != self.uv.shape[:-1]:
            raise SynthesisError(
                f"keypoints must be uv (T, {SKELETON_SLOTS}, 17, 2) and conf (T, "
                f"{SKELETON_SLOTS}, 17) for T = {n} times; got {self.uv.shape}, "
                f"{self.conf.shape}"
            )
        if n and not (np.isfinite(self.time).all() and (np.diff(self.time) > 0).all()):
            raise SynthesisError("keypoint times must be finite and increasing")


def default_model() -> Path:
    """``$AVATARSIM_CONTROLLERPOSE_MODEL`` (a run folder), else ``out/controllerpose``."""
    return Path(os.environ.get(MODEL_ENV, DEFAULT_MODEL))


def default_checkpoint() -> Checkpoint:
    """The model of :func:`default_model` (raises :class:`~.checkpoint.CheckpointError`
    when absent)."""
    return load(default_model())


def model_missing() -> str | None:
    """Why the method cannot run yet (no trained model), or None."""
    if (default_model() / FILE).is_file():
        return None
    return (
        f"no trained model in {default_model()} (avatarsim train controllerpose --out "
        f"{DEFAULT_MODEL}, or set {MODEL_ENV})"
    )


class ControllerPose(Synthesizer):
    """The ControllerPose pipeline on ``skeleton``'s humanoid at the user's height."""

    name = "controllerpose"
    devices = HEADSET_AND_CONTROLLERS

    def __init__(
        self,
        checkpoint: Checkpoint,
        keypoints: KeypointRecording,
        skeleton: Skeleton,
        user_height_m: float,
        ground_feet: bool = True,
    ):
        self.checkpoint = checkpoint
        self.model = checkpoint.model()
        self.keypoints = keypoints
        self.ground_feet = ground_feet
        self.user_height_m = float(user_height_m)
        scaled = skeleton.scaled(self.user_height_m / standing_height(skeleton))
        self.body = build_body(scaled)
        self.ik = HumanoidIK(
            humanoid_model(self.body),
            BODY17,
            position_cost=[HEAD_COST if n == "head" else 1.0 for n in BODY17],
            settings=IKSettings(max_iterations=IK_ITERATIONS_PER_TICK),
        )
        self.rest_sites = self.ik.frame_positions(self.ik.posture)  # (17, 3)
        self.hmd = nominal_attachment("hmd", self.body.skeleton)
        self.lengths = torch.from_numpy(
            (checkpoint.template_lengths * self.user_height_m).astype(np.float32)
        )
        self.reset()

    @property
    def skeleton(self) -> Skeleton:
        return self.body.skeleton

    def settings(self) -> dict:
        return {"ground_feet": self.ground_feet, "trained_epochs": self.checkpoint.epoch}

    def reset_state(self) -> None:
        self._q = self.ik.posture.copy()
        self._solved = False
        self._vr: VRStream | None = None  # the last usable sample of each device so far
        self._camera = -1  # newest camera frame used
        self._targets: np.ndarray | None = None  # (17, 3) world keypoints of that frame
        self._anchors: list[np.ndarray | None] = [None, None]

    def history(self, frames: FrameBatch) -> VRStream:
        """The VR samples so far: the last usable one per device before this batch, then the
        batch's (hmd, left, right controller)."""
        index = self.device_index(frames)
        batch = VRStream(
            frames.timestamps,
            frames.positions[:, index],
            frames.quaternions[:, index],
            frames.usable()[:, index],
            HEADSET_AND_CONTROLLERS,
        )
        if self._vr is None:
            return batch
        return VRStream(
            *(
                np.concatenate([getattr(self._vr, f), getattr(batch, f)])
                for f in ("time", "positions", "quaternions", "valid")
            ),
            HEADSET_AND_CONTROLLERS,
        )

    def world_keypoints(self, cameras: np.ndarray, vr: VRStream) -> tuple[np.ndarray, np.ndarray]:
        """World keypoints ``(C, 17, 3)`` of camera frames ``cameras (C,)`` and which are
        usable ``(C,)`` (a skeleton found, every device seen)."""
        rec = self.keypoints
        features, yaw, usable = frame_features(
            rec.uv[cameras], rec.conf[cameras], rec.time[cameras], vr
        )
        features.check_finite("controllerpose keypoints")
        normalised = self.checkpoint.normaliser.apply(features)
        with torch.no_grad():
            angles = self.model(
                torch.from_numpy(normalised.skeletons),
                torch.from_numpy(normalised.found),
                torch.from_numpy(normalised.vr),
            )
            local = forward_kinematics(angles, self.lengths).numpy().astype(np.float64)
        turned = np.einsum("cij,ckj->cki", heading_matrix(yaw), local)
        # The headset's pose at each frame, the latest usable sample (as the features).
        hmd, _ = latest_sample(vr.time, vr.valid[:, 0], rec.time[cameras])
        rot = quat.normalize(quat.mul(vr.quaternions[hmd, 0], quat.conj(self.hmd.rotation)))
        head = vr.positions[hmd, 0] - quat.rotate(rot, self.hmd.position)
        world = turned + (head - turned[:, INDEX["head"]])[:, None]
        return world, usable

    def grounded(self, targets: np.ndarray) -> np.ndarray:
        """``targets (17, 3)`` with each foot near the floor anchored (module docstring)."""
        out = targets.copy()
        for side, joints in enumerate(FEET):
            idx = list(joints)
            low = (targets[idx, 2] - self.rest_sites[idx, 2]).max() < GROUND_SNAP_M
            if not low:
                self._anchors[side] = None
                continue
            if self._anchors[side] is None:
                anchor = targets[idx].copy()
                anchor[:, 2] = self.rest_sites[idx, 2]
                self._anchors[side] = anchor
            out[idx] = self._anchors[side]
        return out

    def advance(self, frames: FrameBatch) -> Poses:
        vr = self.history(frames)
        newest = np.searchsorted(self.keypoints.time, frames.timestamps + 1e-6, side="right") - 1
        fresh = np.unique(newest[newest > self._camera])
        world, usable = (
            self.world_keypoints(fresh, vr) if fresh.size else (np.zeros((0, 17, 3)), [])
        )
        by_camera = {int(c): (world[i], bool(usable[i])) for i, c in enumerate(fresh)}
        qpos = []
        for camera in newest:
            if camera > self._camera:
                self._camera = int(camera)
                points, ok = by_camera[self._camera]
                if ok:
                    self._targets = points
            if self._targets is not None:
                targets = self.grounded(self._targets) if self.ground_feet else self._targets
                start = self._q if self._solved else self.ik.fitted_root(targets)
                self._q, _, _ = self.ik.solve_frame(targets, start)
                self._solved = True
            qpos.append(self._q.copy())
        seen = vr.valid.any(0)
        if seen.any():  # every kept sample precedes the next batch: one row at its end time
            last = len(vr.time) - 1 - np.argmax(vr.valid[::-1], axis=0)
            cols = np.arange(len(seen))
            self._vr = VRStream(
                vr.time[-1:],
                vr.positions[last, cols][None],
                vr.quaternions[last, cols][None],
                seen[None],
                HEADSET_AND_CONTROLLERS,
            )
        motion = motion_from_qpos(self.body, np.stack(qpos), DEFAULT_RATE_HZ)
        return Poses(motion.root_pos, motion.local_rot)

    def run(self, stream: TrackingStream) -> Motion:
        # Small QPs and a small network: extra threads cost more than they save.
        with threadpool_limits(1, user_api="blas"):
            return super().run(stream)
