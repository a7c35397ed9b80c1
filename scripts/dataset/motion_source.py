"""The motion of one planned window: generated (built-in subject) or cut from a mocap clip.

A built-in window is :func:`avatar_models.generator.generate` of its activity on its subject
(``sample_subject`` drawn from the subject's seed), ``seconds`` long at ``fps``; the window's
seed sets the generator's start phase and personal offsets, so repeats differ. A mocap
window is the clip resampled to ``fps``, cut at a start drawn from the window's seed; a clip
shorter than the window gives all of itself (such samples have fewer frames).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.avatar_models.motion import Motion
from avatarsim.scripts.dataset.config import DatasetConfig
from avatarsim.scripts.dataset.plan import MotionWindow, subject_seed


def window_frames(config: DatasetConfig) -> int:
    """Frames of a full window: the generator's count for ``seconds`` at ``fps``."""
    return int(np.floor(config.window.seconds * config.window.fps + 1e-9)) + 1


@lru_cache(maxsize=4)  # a shard holds a clip's windows one after another
def _clip_at(path: str, fps: float) -> Motion:
    return load_motion(path).resample(fps)


def window_motion(config: DatasetConfig, window: MotionWindow) -> Motion:
    """The window's motion at ``config.window.fps``; ``meta["window"]`` says where it came from
    (``start_frame`` within the resampled clip for mocap)."""
    fps = config.window.fps
    if window.kind == "builtin":
        subject = sample_subject(np.random.default_rng(subject_seed(config, window)))
        motion = generate(window.activity, subject, config.window.seconds, fps, window.seed)
        return motion.replace(meta={**motion.meta, "window": {"start_frame": 0}})
    clip = _clip_at(window.clip, fps)
    n = min(window_frames(config), clip.n_frames)
    start = int(np.random.default_rng(window.seed).integers(0, clip.n_frames - n + 1))
    motion = clip[start : start + n]
    return motion.replace(meta={**motion.meta, "window": {"start_frame": start}})
