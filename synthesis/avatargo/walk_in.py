"""The walk-in sample (AvatarGo §3.2): the six devices while the user stands in a T-pose.

The user stands still in a T-pose before the session and presses the trigger; the devices'
last sample is the calibration sample (:func:`walk_in`). The T-pose is a calibration pose,
not part of the clip: :func:`t_pose` stands the clip's own rig (same bones, same device
attachments and straps) in one, so that the walk-in and the session come from one body.

A rig whose rest pose is a T-pose (the avatar rig, CMU's cgspeed BVH) stands in it. Any
other rig's rest pose says nothing of how its joint frames sit on the body (Bandai's lies
along +Y, every bone along its parent's +Y axis, one leg up, the pelvis's frame a quarter
turn from the chest's), so the T-pose starts from the clip's own frame where both feet are
lowest (the user stands; :func:`standing_frame`), turned upright facing +X
(:func:`~synthesis.ik_baseline.body_frame`), and its limbs are aimed bone by bone from the
trunk outwards (:func:`aim_limbs`): the arms sideways (collarbone to wrist), the legs
straight down (hip to ankle), the feet as they were on the floor. Each bone turns by the
smallest rotation, so the limbs keep the clip's roll: hanging arms raised sideways put the
palms down, as in the avatar rig's T-pose.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import Motion, Skeleton, quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams.vr import VRSetup
from avatarsim.synthesis.base import TrackingFrame
from avatarsim.synthesis.ik_baseline import body_frame, rest_body_frame, stands_upright

WALK_IN_S = 0.5
"""How long the user stands in the T-pose before the trigger (the sample is the last one)."""
RATE_HZ = 90.0
T_POSE_TOLERANCE_DEG = 30.0
"""A rest pose is a T-pose when every arm and leg bone lies within this of its T-pose
direction (our choice: CMU's rest legs stand 20 deg apart, Bandai's bones are 90-180 deg
off)."""
SIDEWAYS = {"l": np.array([0.0, 1.0, 0.0]), "r": np.array([0.0, -1.0, 0.0])}
DOWN = np.array([0.0, 0.0, -1.0])
HALF_TURN_AXIS = np.array([0.0, 1.0, 0.0])
"""A bone pointing exactly opposite its aim (an arm raised straight up) turns through the
front, about the body's left axis."""


def limb_chains(skeleton: Skeleton) -> dict[str, list[int]]:
    """Joint chains of ``skeleton``'s limbs, trunk side first: ``"l_arm"``/``"r_arm"`` from
    the first joint off the trunk (the collarbone) to the wrist, ``"l_leg"``/``"r_leg"``
    from the hip to the ankle, ``"l_foot"``/``"r_foot"`` from the ankle to the ball."""
    rig = identify_rig(skeleton)
    at = {name: skeleton.index(joint) for name, joint in rig.body17.items()}
    trunk = set(skeleton.chain(at["neck"]))

    def between(start: int, end: int) -> list[int]:
        chain = skeleton.chain(end)
        return chain[chain.index(start) :]

    out = {}
    for s in "lr":
        out[f"{s}_arm"] = [j for j in skeleton.chain(at[f"{s}_wrist"]) if j not in trunk]
        out[f"{s}_leg"] = between(at[f"{s}_hip"], at[f"{s}_ankle"])
        out[f"{s}_foot"] = between(at[f"{s}_ankle"], at[f"{s}_foot"])
    return out


def aim_limbs(skeleton: Skeleton, local: np.ndarray, aims: dict[str, np.ndarray]) -> np.ndarray:
    """``local (J, 4)`` with each bone of the chains of :func:`limb_chains` named in ``aims``
    (chain name -> ``(3,)`` unit world direction) turned at its joint, by the smallest
    rotation, onto its direction; chains in ``aims``' order, bones root side first."""
    local = local.copy()
    world = np.empty_like(local)
    chains = limb_chains(skeleton)
    for name, target in aims.items():
        chain = chains[name]
        for joint, child in zip(chain[:-1], chain[1:], strict=True):
            if np.linalg.norm(skeleton.offsets[child]) < 1e-9:
                continue  # a folded joint: the next bone aims it
            for j in skeleton.chain(joint):  # world rotations down to the joint, aims so far
                parent = skeleton.parents[j]
                world[j] = local[j] if parent < 0 else quat.mul(world[parent], local[j])
            bone = quat.rotate(world[joint], skeleton.offsets[child])
            turn = smallest_turn(bone / np.linalg.norm(bone), target)
            # world[joint] becomes turn * world[joint]: in the parent's frame, P^-1 turn P L.
            parent = world[skeleton.parents[joint]]
            local[joint] = quat.mul(quat.mul(quat.conj(parent), turn), world[joint])
    return quat.normalize(local)


def smallest_turn(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """wxyz smallest turn of unit ``u (3,)`` onto unit ``v (3,)``; a half turn about
    :data:`HALF_TURN_AXIS` (perpendicular to both) where they are opposite."""
    w = 1.0 + u @ v
    if w < 1e-9:
        return np.concatenate([[0.0], HALF_TURN_AXIS])
    return quat.normalize(np.concatenate([[w], np.cross(u, v)]))


def is_t_pose(skeleton: Skeleton) -> bool:
    """Whether ``skeleton``'s rest pose stands upright in a T-pose: arms sideways and legs
    down within :data:`T_POSE_TOLERANCE_DEG`."""
    if not stands_upright(skeleton):
        return False
    rest = skeleton.rest_positions() @ rest_body_frame(skeleton)  # body-frame coordinates
    cos_min = np.cos(np.radians(T_POSE_TOLERANCE_DEG))
    for name, chain in limb_chains(skeleton).items():
        if name.endswith("foot"):
            continue
        bones = rest[chain[1:]] - rest[chain[:-1]]
        length = np.linalg.norm(bones, axis=-1)
        aim = SIDEWAYS[name[0]] if name.endswith("arm") else DOWN
        if (bones[length > 1e-9] @ aim < cos_min * length[length > 1e-9]).any():
            return False
    return True


def standing_frame(motion: Motion) -> int:
    """The frame of ``motion`` whose higher ankle is lowest: both feet on the floor."""
    rig = identify_rig(motion.skeleton)
    ankles = motion.skeleton.indices([rig.body17["l_ankle"], rig.body17["r_ankle"]])
    return int(np.argmin(motion.global_positions()[:, ankles, 2].max(1)))


def built_t_pose(motion: Motion) -> np.ndarray:
    """``(J, 4)`` local rotations of a T-pose of ``motion``'s rig facing +X, from its
    :func:`standing_frame` (see the module docstring)."""
    sk = motion.skeleton
    f = standing_frame(motion)
    positions = motion.global_positions()[f]
    upright = body_frame(positions, sk).T  # world -> the standing body's frame
    chains = limb_chains(sk)
    feet = {
        name: upright @ (positions[chains[name][-1]] - positions[chains[name][0]])
        for name in ("l_foot", "r_foot")
    }
    local = motion.local_rot[f].copy()
    local[0] = quat.mul(quat.from_matrix(upright), local[0])
    aims = {f"{s}_arm": SIDEWAYS[s] for s in "lr"} | {f"{s}_leg": DOWN for s in "lr"}
    aims |= {name: d / np.linalg.norm(d) for name, d in feet.items()}
    return aim_limbs(sk, local, aims)


def t_pose(motion: Motion, heading_rad: float, seconds: float = WALK_IN_S) -> Motion:
    """The user of ``motion`` standing still in a T-pose (see the module docstring) at the
    origin, feet on the floor, turned to ``heading_rad``, for ``seconds`` at 90 Hz.

    A rest T-pose stands on its body's feet (:func:`build_body`'s root height, as the
    avatar's in :class:`~synthesis.avatargo.synthesizer.AvatarGo`); a built one with its
    lowest joint on the floor."""
    sk = motion.skeleton
    frames = int(round(seconds * RATE_HZ)) + 1
    heading = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(heading_rad))
    if is_t_pose(sk):
        pose = np.tile(quat.IDENTITY, (sk.n_joints, 1))
        height = build_body(sk).root_height
    else:
        pose = built_t_pose(motion)
        still = Motion(sk, RATE_HZ, np.zeros((1, 3)), pose[None])
        height = -still.global_positions()[0, :, 2].min()
    pose[0] = quat.mul(heading, pose[0])
    local = np.tile(pose, (frames, 1, 1))
    root = np.tile([0.0, 0.0, height], (frames, 1))
    return Motion(sk, RATE_HZ, root, local)


def walk_in(setup: VRSetup, motion: Motion, seed: int, heading_rad: float = 0.0) -> TrackingFrame:
    """The devices' last sample while the user of ``motion`` stands in the T-pose facing
    ``heading_rad`` (the trigger press), sampled by ``setup`` with ``seed`` (the seed of the
    session's stream, so that the devices sit where they sit during the session)."""
    stream = setup.sample(t_pose(motion, heading_rad), seed=seed)
    return TrackingFrame.from_stream(stream, stream.n_samples - 1)
