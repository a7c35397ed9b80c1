"""Poses with known geometry for the Kinect tests: the avatar standing in its T-pose."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.generator import Subject, subject_skeleton


def t_pose(frames: int = 1, fps: float = 30.0, yaw: float = 0.0) -> Motion:
    """The default subject in its rest T-pose (arms along +-Y, facing +X), feet on the floor,
    turned by ``yaw`` about Z, held for ``frames`` frames."""
    skeleton = subject_skeleton(Subject())
    identity = np.tile([1.0, 0.0, 0.0, 0.0], (frames, skeleton.n_joints, 1))
    root = np.tile(skeleton.offsets[0], (frames, 1))
    return Motion(skeleton, fps, root, identity).rotated_about_z(yaw)


def t_pose_walk(frames: int, velocity: tuple[float, float], fps: float = 30.0) -> Motion:
    """The T-pose (facing +X) gliding over the floor at ``velocity`` ``(vx, vy)`` m/s from the
    origin: a trajectory with known geometry."""
    still = t_pose(frames, fps)
    t = np.arange(frames)[:, None] / fps
    root = still.root_pos + np.c_[t * np.asarray(velocity, float)[None], np.zeros(frames)]
    return still.replace(root_pos=root)
