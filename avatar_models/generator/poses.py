"""Joint-angle building blocks shared by activities: trunk, gaze, arms hanging and swinging.

Angles are written for the left side in the rest frame (x forward, y left, z up) and mirrored
for the right side (:func:`~avatar_models.generator.plan.sided`).
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.generator.ik import axis_rotation, euler
from avatarsim.avatar_models.generator.plan import Scene, sided

X_AXIS, Y_AXIS, Z_AXIS = np.eye(3)


def trunk(
    scene: Scene,
    flexion: np.ndarray | float = 0.0,
    twist: np.ndarray | float = 0.0,
    side_bend: np.ndarray | float = 0.0,
) -> np.ndarray:
    """``(T, 3, 3)`` local rotation of each spine joint for whole-spine angles (radians):
    forward ``flexion`` plus the style's stoop, ``twist`` (left turn positive) and
    ``side_bend`` (towards the left positive), shared equally by the three spine joints."""
    n = scene.n_frames
    flex = np.broadcast_to(flexion, (n,)) + np.radians(scene.style.stoop_deg)
    angles = np.stack(
        [np.broadcast_to(side_bend, (n,)) * -1.0, flex, np.broadcast_to(twist, (n,))], axis=1
    )
    return euler(angles / 3.0, "xyz")


def gaze(
    scene: Scene, heading: np.ndarray | float = 0.0, pitch: np.ndarray | float = 0.0
) -> np.ndarray:
    """``(T, 3, 3)`` head world rotation looking along ``heading`` (yaw, radians) and pitched
    down by ``pitch`` plus the style's head pitch."""
    n = scene.n_frames
    down = np.broadcast_to(pitch, (n,)) + np.radians(scene.style.head_pitch_deg)
    return euler(np.stack([np.zeros(n), down, np.broadcast_to(heading, (n,))], axis=1), "xyz")


def arm_angles(
    scene: Scene,
    side: str,
    swing: np.ndarray | float,
    abduction: np.ndarray | float,
    elbow: np.ndarray | float,
) -> dict[str, np.ndarray]:
    """Local rotations of an arm hanging from the shoulder: ``abduction`` (radians from the
    trunk's side, 0 = hanging, pi/2 = T-pose), then ``swing`` forward (positive) about the
    shoulder's lateral axis, and ``elbow`` flexion. Returns ``{joint: (T, 3, 3)}``."""
    n = scene.n_frames
    lower = np.broadcast_to(np.pi / 2 - np.asarray(abduction, dtype=float), (n,))
    upper = axis_rotation(Y_AXIS, -np.broadcast_to(swing, (n,))) @ axis_rotation(X_AXIS, -lower)
    fore = axis_rotation(Z_AXIS, -np.broadcast_to(elbow, (n,)))
    return {
        f"Bip01 {side} UpperArm": sided(upper, side),
        f"Bip01 {side} Forearm": sided(fore, side),
    }


def heading_rotation(yaw: np.ndarray | float, n: int) -> np.ndarray:
    """``(n, 3, 3)`` rotations about +Z by ``yaw`` radians."""
    return axis_rotation(Z_AXIS, np.broadcast_to(yaw, (n,)))
