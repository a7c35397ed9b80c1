"""Motions and streams with known content, built in code (no data files)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import Motion, quat
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams import TrackingStream


def body17_motion(fps: float = 90.0, seconds: float = 2.0) -> Motion:
    """A body17 figure walking along +X while turning, bending and swinging its arms.

    Every joint rotates about a different axis at a different frequency, so that any mix-up
    of joints, frames or time steps changes the device poses.
    """
    skeleton = load_rig("body17").skeleton
    t = np.arange(int(round(seconds * fps)) + 1) / fps
    n, j = t.size, skeleton.n_joints
    freq = 0.5 + 0.1 * np.arange(j)
    phase = 0.7 * np.arange(j)[None, :] + 2.0 * np.pi * freq[None, :] * t[:, None]
    axes = np.stack([np.sin(np.arange(j)), np.cos(np.arange(j)), np.ones(j)], axis=1)
    rotvec = 0.4 * np.sin(phase)[..., None] * axes / np.linalg.norm(axes, axis=1)[:, None]
    local = quat.from_scipy(Rotation.from_rotvec(rotvec.reshape(-1, 3)), (n, j))
    root = np.stack([0.8 * t, 0.1 * np.sin(t), 0.95 + 0.02 * np.sin(4 * t)], axis=1)
    return Motion(skeleton, fps, root, local, meta={"source": "tests"})


def rest_motion(frames: int = 3, root=(0.0, 0.0, 0.95), yaw: float = 0.0) -> Motion:
    """The body17 rest pose (T-pose facing +X), its root at ``root`` turned by ``yaw``."""
    skeleton = load_rig("body17").skeleton
    local = np.zeros((frames, skeleton.n_joints, 4))
    local[..., 0] = 1.0
    local[:, 0] = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(yaw))
    return Motion(skeleton, 90.0, np.tile(np.asarray(root, float), (frames, 1)), local)


def static_stream(samples: int, devices: int, rate_hz: float = 90.0) -> TrackingStream:
    """Devices at rest at the origin with identity orientation, sampled at ``rate_hz``."""
    q = np.zeros((samples, devices, 4))
    q[..., 0] = 1.0
    return TrackingStream(
        device_names=tuple(f"dev{i}" for i in range(devices)),
        timestamps=np.arange(samples) / rate_hz,
        positions=np.zeros((samples, devices, 3)),
        quaternions=q,
        valid=np.ones((samples, devices), bool),
        meta={"rate_hz": rate_hz},
    )


def folder_bytes(root: Path) -> dict[str, bytes]:
    """Every file under ``root`` by its relative path, for byte-for-byte comparisons."""
    files = sorted(p for p in root.rglob("*") if p.is_file())
    return {str(p.relative_to(root)): p.read_bytes() for p in files}
