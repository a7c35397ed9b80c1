"""The CoolMoves motion database: stylised full-body poses indexed by 100 ms hand windows.

Built as in CoolMoves §3.1.2 from any motion library: every trial is resampled to 90 Hz, the
driving points (the two controllers by default) are made head-relative, trials failing the
hand-foot Pearson filter are dropped, and rolling 9-sample windows (50 ms overlap) are cut at
every speed of the augmentation. Each window stands for the full-body pose at its *last*
sample (§3.1.4).

The driving points are where the tracked devices sit on the body (the nominal attachments of
:mod:`render_cams.vr.placements`: HMD between the eyes, controllers in the palms), so database
windows and live queries describe the same points. The hands may be swapped for other points
(:data:`FEET_DRIVE` for limb remapping, §5.3).

Shapes: ``N`` windows, ``P`` poses, ``J`` joints, ``n = 9`` samples, sides ``(left, right)``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from avatarsim.avatar_models import Motion, Skeleton, quat
from avatarsim.avatar_models.library import MotionLibrary
from avatarsim.avatar_models.rigs import RigError, identify_rig
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.render_cams.vr import attachment_poses, nominal_attachment
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.coolmoves import correlation
from avatarsim.synthesis.coolmoves.features import (
    RATE_HZ,
    SPEED_FACTORS,
    WINDOW_SAMPLES,
    search_vectors,
    speed_windows,
    window_stride,
)


@dataclass(frozen=True)
class Drivers:
    """Which tracked points drive the matching, and which limb each side governs.

    Attributes:
        head: the device that is the origin of the head-relative frame.
        left, right: the devices whose windows are matched, one KD-tree each (§3.1.3).
        left_limb, right_limb: body17 joints whose subtrees take their weights from the left
            (right) matches only; every other joint blends both sides (§3.1.4).
    """

    head: str = "hmd"
    left: str = "left_controller"
    right: str = "right_controller"
    left_limb: str = "l_shoulder"
    right_limb: str = "r_shoulder"

    @property
    def devices(self) -> tuple[str, str, str]:
        return (self.head, self.left, self.right)


HANDS_DRIVE = Drivers()
"""The paper's setup: headset and two hand controllers, arms governed by their own hand."""
FEET_DRIVE = Drivers(
    left="left_foot_tracker", right="right_foot_tracker", left_limb="l_hip", right_limb="r_hip"
)
"""Limb remapping (§5.3): windows of the feet, legs governed by their own foot."""


@dataclass(frozen=True, eq=False)
class Database:
    """A built CoolMoves database.

    Attributes:
        skeleton: the output rig (the rig file's skeleton when the motions use a known rig).
        drivers: the driving points.
        poses: ``(P, J, 4)`` local rotations (wxyz) of the represented poses.
        entry_pose: ``(N,)`` index into ``poses`` of each window's pose.
        windows: ``(N, n, 2, 3)`` head-relative positions of the left and right driver.
        search: ``(2, N, 3n)`` per side, :func:`~.features.search_vectors` of the windows.
        limb_masks: ``(2, J)`` bool, joints governed by the left / right side only.
        mean_pose: ``(J, 4)`` average pose, shown before the first match.
        clips: per source motion, its labels, correlation and whether it was kept.
    """

    skeleton: Skeleton
    drivers: Drivers
    poses: np.ndarray
    entry_pose: np.ndarray
    windows: np.ndarray
    search: np.ndarray
    limb_masks: np.ndarray
    mean_pose: np.ndarray
    clips: list[dict[str, Any]] = field(default_factory=list)

    @property
    def n_windows(self) -> int:
        return int(self.entry_pose.shape[0])

    @property
    def window_samples(self) -> int:
        return int(self.windows.shape[1])

    def window_clips(self) -> np.ndarray:
        """``(N,)`` index into :attr:`clips` of the source motion of every window."""
        kept = [i for i, c in enumerate(self.clips) if c["kept"]]
        return np.repeat(kept, [self.clips[i]["windows"] for i in kept])


def labels(motion: Motion) -> dict[str, Any]:
    """Activity, subject and style of a motion from its ``meta`` (library or generator)."""
    meta = motion.meta
    subject = meta.get("subject")
    style = meta.get("style") or (subject.get("style") if isinstance(subject, dict) else None)
    return {
        "activity": meta.get("activity"),
        "subject": meta.get("subject_id", subject if not isinstance(subject, dict) else None),
        "style": style,
        "take": meta.get("take"),
    }


def _motions(source: Sequence[Motion] | MotionLibrary | Iterable[Motion]) -> list[Motion]:
    if isinstance(source, MotionLibrary):
        return [clip.load() for clip in source]
    return list(source)


def _reference_skeleton(motion: Motion) -> Skeleton:
    """The rig file's skeleton for ``motion``'s topology, else the motion's own skeleton."""
    try:
        rig = identify_rig(motion.skeleton)
    except RigError:
        return motion.skeleton
    return rig.skeleton if rig.skeleton.same_topology(motion.skeleton) else motion.skeleton


def limb_masks(skeleton: Skeleton, drivers: Drivers) -> np.ndarray:
    """``(2, J)`` joints in the subtree of each driver's limb joint (inclusive)."""
    rig = identify_rig(skeleton)
    masks = np.zeros((2, skeleton.n_joints), bool)
    for side, limb in enumerate((drivers.left_limb, drivers.right_limb)):
        root = skeleton.index(rig.body17[limb])
        masks[side, root] = True
        for j in range(root + 1, skeleton.n_joints):
            masks[side, j] = masks[side, skeleton.parents[j]]
    return masks


def driver_positions(motion: Motion, drivers: Drivers) -> tuple[np.ndarray, np.ndarray]:
    """World positions of the drivers on ``motion``: head ``(T, 3)`` and sides ``(T, 2, 3)``."""
    attachments = [nominal_attachment(d, motion.skeleton) for d in drivers.devices]
    positions, _ = attachment_poses(motion, attachments)
    return positions[:, 0], positions[:, 1:]


def _trial_windows(
    motion: Motion, drivers: Drivers, speeds: Sequence[float], n: int
) -> tuple[np.ndarray, np.ndarray]:
    """Windows ``(E, n, 2, 3)`` and the frame each ends at ``(E,)``, over all speeds."""
    head, sides = driver_positions(motion, drivers)
    relative = sides - head[:, None]
    stride = window_stride(n)
    windows, ends = [], []
    for speed in speeds:
        first = int(np.ceil(speed * (n - 1) - 1e-9))
        # A common grid of window ends for every speed, so augmented windows share poses.
        e = np.arange(n - 1, motion.n_frames, stride)
        e = e[e >= first]
        windows.append(speed_windows(relative, e, speed, n))
        ends.append(e)
    return np.concatenate(windows), np.concatenate(ends)


def hands_and_feet(motion: Motion) -> tuple[np.ndarray, np.ndarray]:
    """Head-relative wrists and ankles ``(T, 2, 3)`` each, for the correlation filter."""
    rig = identify_rig(motion.skeleton)
    pos = motion.global_positions()
    head = pos[:, motion.skeleton.index(rig.body17["head"])]
    pick = {
        k: motion.skeleton.indices([rig.body17[f"l_{k}"], rig.body17[f"r_{k}"]])
        for k in ("wrist", "ankle")
    }
    return pos[:, pick["wrist"]] - head[:, None], pos[:, pick["ankle"]] - head[:, None]


def build_database(
    source: Sequence[Motion] | MotionLibrary,
    drivers: Drivers = HANDS_DRIVE,
    speeds: Sequence[float] = SPEED_FACTORS,
    correlation_threshold: float = correlation.CORRELATION_THRESHOLD,
    window: int = WINDOW_SAMPLES,
) -> Database:
    """A :class:`Database` from motions (or every clip of a :class:`MotionLibrary`).

    All motions must share one skeleton topology (their proportions may differ: only local
    rotations are stored). Raises :class:`SynthesisError` if none is given, topologies differ
    or no trial passes the correlation filter.
    """
    motions = _motions(source)
    if not motions:
        raise SynthesisError("a CoolMoves database needs at least one motion")
    reference = _reference_skeleton(motions[0])
    poses, entry_pose, windows, clips = [], [], [], []
    n_poses = 0
    for i, motion in enumerate(motions):
        if not motion.skeleton.same_topology(reference):
            raise SynthesisError(
                f"motion {i} has another skeleton topology ({motion.skeleton!r}) than the "
                f"first ({reference!r}); a database holds one rig"
            )
        motion = motion_at_rate(motion, RATE_HZ)
        score = correlation.hand_foot_correlation(*hands_and_feet(motion))
        kept = score >= correlation_threshold and motion.n_frames >= window
        clips.append({**labels(motion), "correlation": score, "kept": bool(kept)})
        if not kept:
            continue
        trial_windows, ends = _trial_windows(motion, drivers, speeds, window)
        unique_ends, pose_of = np.unique(ends, return_inverse=True)
        poses.append(motion.local_rot[unique_ends])
        entry_pose.append(pose_of + n_poses)
        windows.append(trial_windows)
        n_poses += unique_ends.size
        clips[-1]["windows"] = int(ends.size)
    if not poses:
        raise SynthesisError(
            f"no motion passed the hand-foot correlation filter (threshold "
            f"{correlation_threshold}); scores: {[round(c['correlation'], 3) for c in clips]}"
        )
    all_poses = quat.make_continuous(np.concatenate(poses), axis=0)
    all_windows = np.concatenate(windows)
    search = np.stack([search_vectors(all_windows[:, :, s]) for s in (0, 1)])
    hemisphere = np.where(all_poses[..., :1] < 0, -all_poses, all_poses)
    mean_pose = hemisphere.sum(axis=0)
    return Database(
        skeleton=reference,
        drivers=drivers,
        poses=all_poses,
        entry_pose=np.concatenate(entry_pose),
        windows=all_windows,
        search=np.ascontiguousarray(search),
        limb_masks=limb_masks(reference, drivers),
        mean_pose=mean_pose / np.linalg.norm(mean_pose, axis=-1, keepdims=True),
        clips=clips,
    )
