"""Recording and playback of avatar animations (MoveBox §III-B1, §III-B2): "record the
animations they create via motion capture and replay them across any of the Microsoft
Rocketbox avatars", with cropping and looping.

A recording is a :class:`~avatar_models.Motion` on an avatar rig, saved as BVH or as NPZ
with its metadata through :mod:`avatar_models.formats`. Rocketbox avatars share one
skeleton layout (the 3ds Max Biped) and differ in proportions, so playback on another avatar
copies the local joint rotations and scales the root path by the ratio of leg lengths
(hip height at rest), which keeps the feet on the floor and the stride to the new legs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models import Motion, Skeleton
from avatarsim.avatar_models.formats import load_motion, save_motion
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.movebox.similarity import loop_points


def hip_height(skeleton: Skeleton) -> float:
    """Rest height of the hips above the lowest joint (the leg length, for root scaling)."""
    rig = identify_rig(skeleton)
    rest = skeleton.rest_positions()[:, 2]
    hips = skeleton.indices([rig.body17["l_hip"], rig.body17["r_hip"]])
    return float(rest[hips].mean() - rest.min())


def playback(recording: Motion, avatar: Skeleton) -> Motion:
    """``recording`` played on ``avatar`` (same joint layout, any proportions).

    Raises:
        SynthesisError: ``avatar`` has another joint layout.
    """
    if not recording.skeleton.same_topology(avatar):
        raise SynthesisError(
            f"a recording on {recording.skeleton!r} plays on avatars of the same joint layout; "
            f"{avatar!r} differs"
        )
    scale = hip_height(avatar) / hip_height(recording.skeleton)
    return recording.replace(skeleton=avatar, root_pos=recording.root_pos * scale)


def crop(recording: Motion, start_s: float, stop_s: float) -> Motion:
    """The frames of ``recording`` from ``start_s`` to ``stop_s`` (seconds, inclusive).

    Raises:
        SynthesisError: an empty or reversed range, or one outside the recording.
    """
    last = recording.duration_s
    if not (0.0 <= start_s < stop_s and start_s <= last):
        raise SynthesisError(
            f"crop range {start_s:g}-{stop_s:g} s is empty or outside the recording (0-{last:g} s)"
        )
    first = int(np.ceil(start_s * recording.fps - 1e-9))
    end = int(np.floor(min(stop_s, last) * recording.fps + 1e-9)) + 1
    return recording[first:end]


def looped(recording: Motion, duration_s: float, search_s: float = 1.0) -> Motion:
    """``recording`` trimmed at its most similar frame pair (:func:`loop_points`, searched in
    the first and last ``search_s``) and repeated to last ``duration_s``; each cycle's root
    path starts where the last one's would have gone on (horizontally), so a walk walks on."""
    start, stop = loop_points(recording.local_rot, max(1, int(round(search_s * recording.fps))))
    period = stop - start
    frames = int(round(duration_s * recording.fps)) + 1
    k = np.arange(frames)
    cycle, phase = k // period, start + k % period
    advance = recording.root_pos[stop] - recording.root_pos[start]
    advance[2] = 0.0
    return recording.replace(
        root_pos=recording.root_pos[phase] + cycle[:, None] * advance,
        local_rot=recording.local_rot[phase],
        meta={**recording.meta, "loop_frames": [start, stop]},
    )


def save_recording(recording: Motion, path: str | Path) -> Path:
    """Write ``recording`` (``.bvh`` or ``.npz``, which also keeps ``meta``)."""
    return save_motion(recording, path)


def load_recording(path: str | Path) -> Motion:
    """Read a recording written by :func:`save_recording`."""
    return load_motion(path)
