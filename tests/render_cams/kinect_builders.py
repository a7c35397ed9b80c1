"""Poses with known geometry for the Kinect tests: the avatar standing in its T-pose."""

from __future__ import annotations

import numpy as np

from avatar_models import Motion
from avatar_models.generator import Subject, subject_skeleton


def t_pose(frames: int = 1, fps: float = 30.0, yaw: float = 0.0) -> Motion:
    """The default subject in its rest T-pose (arms along +-Y, facing +X), feet on the floor,
    turned by ``yaw`` about Z, held for ``frames`` frames."""
    skeleton = subject_skeleton(Subject())
    identity = np.tile([1.0, 0.0, 0.0, 0.0], (frames, skeleton.n_joints, 1))
    root = np.tile(skeleton.offsets[0], (frames, 1))
    return Motion(skeleton, fps, root, identity).rotated_about_z(yaw)
