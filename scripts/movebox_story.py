"""The storytelling scene of ``avatarsim eval movebox`` (MoveBox §III-B):
actors recorded one at a time through a simulated Kinect, played back together on avatars of
other sizes, one speaking from an audio file. Writes ``story.mp4`` (imageio) and
``story.xml`` (MJCF; ``python -m mujoco.viewer --mjcf story.xml``, then step the keyframes).
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import imageio.v2 as imageio
import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.fileio import write_atomic
from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams.kinect import Kinect
from avatarsim.synthesis.movebox import MoveBox
from avatarsim.synthesis.movebox.face import lip_sync, read_wav
from avatarsim.synthesis.movebox.recording import playback
from avatarsim.synthesis.movebox.resize import resized
from avatarsim.synthesis.movebox.storytelling import (
    ACTOR_RGBA,
    Actor,
    drawn_bones,
    scene_spec,
    stage,
)

CAST = (
    # activity, performer height, avatar height, mark (x, y), facing (rad)
    ("wave", 1.62, 1.70, (0.0, 0.0), 0.0),
    ("box", 1.85, 1.80, (0.3, 1.4), -0.6),
    ("squat", 1.70, 1.58, (0.3, -1.4), 0.6),
)
"""Who plays what: the first actor speaks."""
FRAME_SIZE = (640, 360)
PIXELS_PER_M = 95.0
KEY_FPS = 10.0


def record_take(activity: str, height_m: float, seconds: float, seed: int) -> Motion:
    """One actor alone in front of a Kinect V2, recorded by MoveBox on an avatar of the
    performer's own size (30 Hz: the takes are played back at the sensor's rate), from the
    skeleton the Kinect tracks on its depth."""
    performer = generate(activity, Subject(height_m=height_m), seconds, 90.0, seed)
    kinect = Kinect("kinect-v2").sample(performer, seed).skeleton
    avatar = resized(load_rig("avatar").skeleton, height_m)
    return MoveBox(kinect, avatar).record(30.0)


def cast(seconds: float, seed: int, audio: Path | None) -> list[Actor]:
    """The :data:`CAST`, each take played back on an avatar of another size."""
    speech = None
    if audio is not None:
        rate, samples = read_wav(audio)
        speech = lip_sync(samples, rate, 30.0)
    actors = []
    for i, (activity, performer_m, avatar_m, mark, facing) in enumerate(CAST):
        take = record_take(activity, performer_m, seconds, seed + i)
        avatar = resized(load_rig("avatar").skeleton, avatar_m)
        actors.append(
            Actor(activity, playback(take, avatar), mark, facing, speech if i == 0 else None)
        )
    return actors


def draw(motions: list[Motion], frame: int) -> np.ndarray:
    """``(H, W, 3)`` RGB: every actor's bones seen from the front (+X looks at the viewer)."""
    w, h = FRAME_SIZE
    image = np.full((h, w, 3), 235, np.uint8)
    cv2.line(image, (0, h - 20), (w, h - 20), (150, 150, 150), 2)
    for a, motion in enumerate(motions):
        pos = motion.global_positions()[min(frame, motion.n_frames - 1)]
        u = w / 2 - pos[:, 1] * PIXELS_PER_M  # the scene's +Y is the viewer's left
        v = h - 20 - pos[:, 2] * PIXELS_PER_M
        colour = tuple(int(255 * c) for c in ACTOR_RGBA[a % len(ACTOR_RGBA)][:3])
        for p, c in drawn_bones(motion):
            cv2.line(image, (int(u[p]), int(v[p])), (int(u[c]), int(v[c])), colour, 3, cv2.LINE_AA)
    return image


def write_story(out: Path, seconds: float, seed: int, audio: Path | None) -> dict:
    """Record, stage and write the scene into ``out``; returns what was written."""
    rng = np.random.default_rng([seed, 14])
    actors = cast(seconds, seed, audio)
    motions = stage(actors, seconds, rng)
    out.mkdir(parents=True, exist_ok=True)
    video = out / "story.mp4"
    partial = out / "story.partial.mp4"
    frames = [draw(motions, t) for t in range(motions[0].n_frames)]
    imageio.mimwrite(partial, frames, fps=motions[0].fps, macro_block_size=8)
    os.replace(partial, video)
    scene = write_atomic(out / "story.xml", scene_spec(motions, KEY_FPS).to_xml())
    return {
        "video": str(video),
        "scene": str(scene),
        "actors": [a.name for a in actors],
        "speaker": actors[0].name if audio is not None else None,
        "frames": motions[0].n_frames,
        "seed": seed,
    }
