"""A compact, positions-only reading of CoolMoves §3.1: the independent reference that
``synthesis.coolmoves`` (which blends joint rotations) is ablated against
(:mod:`tests.measurements.coolmoves_ablation`).

It shares the database's windows and search vectors (§3.1.2: 9 samples, 50 % overlap, the
speed augmentation, the hand-foot filter) and the alignment equation (§3.1.4, c_i from 0), and
differs from the method in what it blends and in what it leaves out:

- every database pose is stored as its ``body17`` joints relative to the headset point
  (forward kinematics of the database rig), and matches are blended as positions;
- the k nearest windows per hand are always blended (no distance threshold), by normalised
  inverse distance; the arms take their own hand's matches, every other joint the mean of both;
- an EWMA of fixed weight ``ewma_weight`` smooths the head-relative joints;
- no bone scaling to the user, no joint limits: the output is the headset position plus the
  blended head-relative joints.

Shapes: ``T`` frames, ``P`` poses, ``k`` matches per hand, 17 ``body17`` joints.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import Motion, body17
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams import TrackingStream
from avatarsim.synthesis.base import on_clock, usable_mask
from avatarsim.synthesis.coolmoves import Database
from avatarsim.synthesis.coolmoves.alignment import alignment_yaw
from avatarsim.synthesis.coolmoves.blend import inverse_distance_weights
from avatarsim.synthesis.coolmoves.database import driver_positions
from avatarsim.synthesis.coolmoves.features import search_vectors, sliding_windows
from avatarsim.synthesis.coolmoves.knn import K_NEIGHBOURS

ARMS = {
    side: [body17.BODY17.index(f"{side}_{p}") for p in ("shoulder", "elbow", "wrist")]
    for side in "lr"
}
"""body17 indices of each arm (the joints that take their own hand's matches, §3.1.4)."""


def head_relative_joints(database: Database) -> np.ndarray:
    """``(P, 17, 3)`` body17 joints of every database pose, relative to its headset point."""
    poses = database.poses
    motion = Motion(database.skeleton, 90.0, np.zeros((len(poses), 3)), poses)
    head, _ = driver_positions(motion, database.drivers)
    return body17_positions(motion) - head[:, None]


def synthesize(
    database: Database,
    stream: TrackingStream,
    k: int = K_NEIGHBOURS,
    ewma_weight: float = 0.5,
    align: bool = True,
) -> np.ndarray:
    """``(T, 17, 3)`` world body17 joints for every sample of ``stream`` (on its 90 Hz
    clock). The first ``n - 1`` samples, before a full window, repeat the first output."""
    from scipy.spatial import cKDTree

    clocked = on_clock(stream)
    idx = [clocked.device(d) for d in database.drivers.devices]
    pos = clocked.positions[:, idx]  # (T, 3, 3): head, left, right
    ok = usable_mask(clocked)[:, idx].all(axis=1)
    # Untracked samples hold the last tracked ones (this reference has no validity logic).
    last = np.maximum.accumulate(np.where(ok, np.arange(ok.size), 0))
    pos = pos[last]
    rel = pos[:, 1:] - pos[:, :1]  # (T, 2, 3)
    n, t = database.window_samples, rel.shape[0]
    ends = np.arange(n - 1, t)
    windows = sliding_windows(rel, ends, n)  # (E, n, 2, 3)
    joints = head_relative_joints(database)
    blended = []
    for side in (0, 1):
        tree = cKDTree(database.search[side])
        dist, entry = tree.query(search_vectors(windows[:, :, side]), k=[*range(1, k + 1)])
        w = inverse_distance_weights(dist)  # (E, k)
        cloud = joints[database.entry_pose[entry]]  # (E, k, 17, 3)
        if align:
            yaw = alignment_yaw(windows, database.windows[entry])  # (E, k)
            c, s = np.cos(yaw), np.sin(yaw)
            x, y = cloud[..., 0], cloud[..., 1]
            cloud = np.stack(
                [
                    c[..., None] * x - s[..., None] * y,
                    s[..., None] * x + c[..., None] * y,
                    cloud[..., 2],
                ],
                axis=-1,
            )
        blended.append(np.einsum("ek,ekjc->ejc", w, cloud))
    out = 0.5 * (blended[0] + blended[1])
    out[:, ARMS["l"]] = blended[0][:, ARMS["l"]]
    out[:, ARMS["r"]] = blended[1][:, ARMS["r"]]
    smoothed = np.empty_like(out)
    state = out[0]
    for e in range(out.shape[0]):
        state = ewma_weight * out[e] + (1.0 - ewma_weight) * state
        smoothed[e] = state
    smoothed = np.concatenate([np.repeat(smoothed[:1], n - 1, axis=0), smoothed])
    return pos[:, 0, None] + smoothed
