"""The paper's storytelling use (MoveBox §III-B1, §III-B2): "the creation of multi-avatar
scenes by a single creator": takes recorded one actor at a time, played back together on
different avatars, looped for as long as the scene lasts, one of them speaking.

:func:`stage` places each actor's take in the scene (looped at its most similar frames,
moved to its mark and turned to face its direction, with procedural blinking and, for the
speaker, lip sync masked onto the face); :func:`scene_spec` builds a MuJoCo scene of the
result that MuJoCo's viewer opens: each bone a capsule on a mocap body, one keyframe per
frame (step through them in the viewer's keyframe panel).

Shapes: ``A`` actors, ``T`` scene frames, ``J`` joints, ``E`` drawn bones.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from avatarsim.avatar_models import Motion, quat
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.movebox.face import LipSync, blinks, face_motion
from avatarsim.synthesis.movebox.masks import Layer, compose
from avatarsim.synthesis.movebox.recording import looped

MIN_BONE_M = 0.02
"""Bones shorter than this are not drawn (finger joints, face)."""
ACTOR_RGBA = ((0.85, 0.35, 0.3, 1.0), (0.3, 0.55, 0.85, 1.0), (0.4, 0.75, 0.4, 1.0))


@dataclass(frozen=True, eq=False)
class Actor:
    """One actor of the scene.

    Attributes:
        name: a label (MJCF names derive from it).
        take: the actor's recording on an avatar rig (any proportions).
        mark: ``(x, y)`` metres, where the take's first frame stands.
        facing: yaw (radians) of the take in the scene.
        speech: the actor's lip sync (the speaker), or None.
    """

    name: str
    take: Motion
    mark: tuple[float, float] = (0.0, 0.0)
    facing: float = 0.0
    speech: LipSync | None = None


def stage(actors: list[Actor], duration_s: float, rng: np.random.Generator) -> list[Motion]:
    """Each actor's take in the scene for ``duration_s`` (module docstring), at the takes'
    common frame rate.

    Raises:
        SynthesisError: no actor, or takes at different frame rates.
    """
    if not actors:
        raise SynthesisError("a scene needs at least one actor")
    fps = actors[0].take.fps
    if any(abs(a.take.fps - fps) > 1e-9 for a in actors):
        raise SynthesisError("the takes of a scene must share one frame rate; resample them")
    out = []
    for actor in actors:
        body = looped(actor.take, duration_s)
        start = body.root_pos[0] * np.array([1.0, 1.0, 0.0])
        body = body.translated(-start).rotated_about_z(actor.facing)
        body = body.translated(np.array([*actor.mark, 0.0]))
        jaw = actor.speech.jaw if actor.speech is not None else np.zeros(1)
        face = face_motion(body.skeleton, fps, jaw, blinks(duration_s, fps, rng))
        out.append(compose(body, [Layer(face[: body.n_frames], "face")]))
    return out


def drawn_bones(motion: Motion) -> np.ndarray:
    """``(E, 2)`` (parent, child) joint pairs drawn as capsules."""
    sk = motion.skeleton
    child = np.flatnonzero((sk.parents >= 0) & (sk.bone_lengths >= MIN_BONE_M))
    return np.stack([sk.parents[child], child], axis=1)


def scene_spec(motions: list[Motion], key_fps: float) -> mujoco.MjSpec:
    """A MuJoCo scene of the staged ``motions`` (:func:`stage`): a floor, a light, each bone
    a capsule on a mocap body, and one keyframe every ``1 / key_fps`` seconds."""
    spec = mujoco.MjSpec()
    spec.modelname = "movebox_story"
    world = spec.worldbody
    world.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[6, 6, 0.1], rgba=[0.8, 0.8, 0.8, 1])
    world.add_light(pos=[0, 0, 4], dir=[0, 0, -1])
    fps = motions[0].fps
    step = max(1, int(round(fps / key_fps)))
    poses_pos, poses_quat = [], []
    for a, motion in enumerate(motions):
        bones = drawn_bones(motion)
        positions = motion.global_positions()[::step]
        start, end = positions[:, bones[:, 0]], positions[:, bones[:, 1]]
        lengths = motion.skeleton.bone_lengths[bones[:, 1]]
        for child, length in zip(bones[:, 1], lengths, strict=True):
            body = world.add_body(name=f"a{a}_{motion.skeleton.names[child]}", mocap=True)
            body.add_geom(
                type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                size=[0.025, 0.5 * length, 0],
                rgba=list(ACTOR_RGBA[a % len(ACTOR_RGBA)]),
                contype=0,
                conaffinity=0,
            )
        poses_pos.append(0.5 * (start + end))
        poses_quat.append(quat.shortest_arc(np.array([0.0, 0.0, 1.0]), end - start))
    mpos = np.concatenate(poses_pos, axis=1)
    mquat = quat.normalize(np.concatenate(poses_quat, axis=1))
    for k in range(mpos.shape[0]):
        spec.add_key(
            name=f"frame{k}", time=k * step / fps, mpos=mpos[k].ravel(), mquat=mquat[k].ravel()
        )
    return spec
