"""A motion plan (trajectories and targets over time) and its realisation as a :class:`Motion`.

Each activity fills a :class:`Plan`: root path, pelvis and spine rotations, the head's wanted
world orientation, angle-driven joints, and IK targets for the limbs. :func:`realise` turns it
into local joint rotations on the subject's avatar skeleton: spine by angle curves, head by
stabilisation (the neck and head undo the trunk's motion to hold the planned gaze), legs and
arms by analytic two-bone IK, fingers by a curl amount. Rotations are ``(T, 3, 3)`` matrices.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.generator.ik import (
    axis_rotation,
    scale_rotation,
    twist_about,
    two_bone_ik,
)
from avatarsim.avatar_models.generator.subject import Style, Subject
from avatarsim.avatar_models.motion import Motion, forward_kinematics
from avatarsim.avatar_models.skeleton import Skeleton

SIDES = ("L", "R")
# Reflection across the sagittal plane; M R M is the mirror image of a rotation R.
MIRROR = np.diag([1.0, -1.0, 1.0])
# Middle-joint hinge axes (local frame) signed so that a positive angle flexes the joint.
KNEE_HINGE = np.array([0.0, 1.0, 0.0])
ELBOW_HINGE = {"L": np.array([0.0, 0.0, -1.0]), "R": np.array([0.0, 0.0, 1.0])}
# Full-fist flexion (degrees) of the finger joints, proximal to distal; thumb smaller.
FIST_DEG = {"": 80.0, "1": 95.0, "2": 65.0}
THUMB_FIST_DEG = {"0": 15.0, "01": 35.0, "02": 50.0}
# Flexion axes in the left hand's frame (fingers point +Y, palm down): fingertips move to -Z.
FINGER_AXIS = np.array([-1.0, 0.0, 0.0])
THUMB_AXIS = np.array([-0.8, 0.5, 0.0]) / np.hypot(0.8, 0.5)


def sided(rot_left: np.ndarray, side: str) -> np.ndarray:
    """``(..., 3, 3)`` rotations written for the left side, as they apply to ``side`` (the
    right side gets the mirror image, conjugated by the sagittal reflection)."""
    return rot_left if side == "L" else MIRROR @ rot_left @ MIRROR


@dataclass(frozen=True)
class Scene:
    """What an activity needs to know: the body, its style, the frame times and the rng."""

    skeleton: Skeleton
    subject: Subject
    times: np.ndarray
    rng: np.random.Generator

    @property
    def n_frames(self) -> int:
        return self.times.size

    @property
    def fps(self) -> float:
        return 1.0 / (self.times[1] - self.times[0]) if self.n_frames > 1 else 1.0

    @property
    def style(self) -> Style:
        return self.subject.effect

    def offset(self, joint: str) -> np.ndarray:
        return self.skeleton.offsets[self.skeleton.index(joint)]

    def rest(self, joint: str) -> np.ndarray:
        """``(3,)`` world rest position of ``joint`` with the root at its rest offset."""
        sk = self.skeleton
        return sk.rest_positions()[sk.index(joint)] + sk.offsets[0]

    @property
    def leg_length(self) -> float:
        """Hip to ankle with the knee straight."""
        return float(sum(np.linalg.norm(self.offset(f"Bip01 L {j}")) for j in ("Calf", "Foot")))

    def constant(self, rot: np.ndarray) -> np.ndarray:
        """``(T, 3, 3)`` copies of one rotation."""
        return np.broadcast_to(rot, (self.n_frames, 3, 3)).copy()


@dataclass
class LimbTarget:
    """IK goal of an arm or a leg: the end joint's world position, the middle joint's pole
    direction, and optionally the end joint's world rotation (foot flat, fist turned)."""

    position: np.ndarray  # (T, 3)
    pole: np.ndarray  # (T, 3)
    rotation: np.ndarray | None = None  # (T, 3, 3)


@dataclass
class Plan:
    """Everything an activity decides, over ``T`` frames.

    Attributes:
        root_pos: ``(T, 3)`` world position of ``Bip01`` (pelvis centre).
        root_rot: ``(T, 3, 3)`` world rotation of ``Bip01`` (heading, body pitch when swimming).
        pelvis: ``(T, 3, 3)`` local rotation of ``Bip01 Pelvis`` (sway, tilt, rotation).
        spine: ``(T, 3, 3)`` local rotation of each of the three spine joints.
        head: ``(T, 3, 3)`` wanted world rotation of the head (gaze).
        contacts: ``(T, 2)`` planned foot contacts (left, right).
        joints: local rotations of angle-driven joints, ``{joint name: (T, 3, 3)}``.
        legs, arms: IK targets per side (``"L"``, ``"R"``); sides absent here keep ``joints``.
        fist: ``(T, 2)`` finger curl in ``[0, 1]`` (left, right); 0 is an open flat hand.
        meta: activity-specific facts for ``Motion.meta`` (e.g. ladder rung heights).
    """

    root_pos: np.ndarray
    root_rot: np.ndarray
    pelvis: np.ndarray
    spine: np.ndarray
    head: np.ndarray
    contacts: np.ndarray
    joints: dict[str, np.ndarray] = field(default_factory=dict)
    legs: dict[str, LimbTarget] = field(default_factory=dict)
    arms: dict[str, LimbTarget] = field(default_factory=dict)
    fist: np.ndarray | None = None
    meta: dict[str, Any] = field(default_factory=dict)


def _finger_rotations(scene: Scene, fist: np.ndarray) -> dict[str, np.ndarray]:
    """Local rotations of every finger joint for curl amounts ``fist (T, 2)``."""
    out = {}
    for s, side in enumerate(SIDES):
        for digit in "1234":
            for seg, deg in FIST_DEG.items():
                rot = axis_rotation(FINGER_AXIS, np.radians(deg) * fist[:, s])
                out[f"Bip01 {side} Finger{digit}{seg}"] = sided(rot, side)
        for seg, deg in THUMB_FIST_DEG.items():
            rot = axis_rotation(THUMB_AXIS, np.radians(deg) * fist[:, s])
            out[f"Bip01 {side} Finger{seg}"] = sided(rot, side)
    return out


def _motion(scene: Scene, plan: Plan, local: np.ndarray) -> Motion:
    return Motion(scene.skeleton, scene.fps, plan.root_pos, quat.from_matrix(local, True))


def realise(scene: Scene, plan: Plan) -> Motion:
    """The plan as a motion on ``scene.skeleton`` (``meta`` is left for the caller)."""
    return _motion(scene, plan, realise_local(scene, plan))


def realise_local(scene: Scene, plan: Plan) -> np.ndarray:
    """The plan's local joint rotations ``(T, J, 3, 3)`` on ``scene.skeleton`` (what
    :func:`realise` turns into a motion)."""
    sk = scene.skeleton
    idx = sk.index
    local = np.broadcast_to(np.eye(3), (scene.n_frames, sk.n_joints, 3, 3)).copy()
    local[:, 0] = plan.root_rot
    local[:, idx("Bip01 Pelvis")] = plan.pelvis
    for spine in ("Bip01 Spine", "Bip01 Spine1", "Bip01 Spine2"):
        local[:, idx(spine)] = plan.spine
    if plan.fist is not None:
        for name, rot in _finger_rotations(scene, plan.fist).items():
            local[:, idx(name)] = rot
    for name, rot in plan.joints.items():
        local[:, idx(name)] = rot

    # Head stabilisation: neck and head together turn the upper trunk's frame into the gaze;
    # the neck takes 40 %. Clavicles hang from the neck in a Biped, so they undo the neck's
    # share to keep the shoulders with the chest.
    glob = forward_kinematics(sk, plan.root_pos, local, [idx("Bip01 Spine2")])[1]
    needed = np.swapaxes(glob[:, idx("Bip01 Spine2")], -1, -2) @ plan.head
    neck = scale_rotation(needed, 0.4)
    local[:, idx("Bip01 Neck")] = neck
    local[:, idx("Bip01 Head")] = np.swapaxes(neck, -1, -2) @ needed
    for side in SIDES:
        c = idx(f"Bip01 {side} Clavicle")
        local[:, c] = np.swapaxes(neck, -1, -2) @ local[:, c]

    leg, arm = ("Thigh", "Calf", "Foot"), ("UpperArm", "Forearm", "Hand")
    limbs = [(s, t, leg, KNEE_HINGE) for s, t in plan.legs.items()]
    limbs += [(s, t, arm, ELBOW_HINGE[s]) for s, t in plan.arms.items()]
    roots = [idx(f"Bip01 {side} {joints[0]}") for side, _, joints, _ in limbs]
    pos, glob = forward_kinematics(sk, plan.root_pos, local, roots)
    for side, target, joints, hinge in limbs:
        u, m, e = (idx(f"Bip01 {side} {j}") for j in joints)
        upper_local, middle_local, upper_world = two_bone_ik(
            pos[:, u],
            glob[:, sk.parents[u]],
            sk.offsets[m],
            sk.offsets[e],
            hinge,
            target.position,
            target.pole,
        )
        if target.rotation is not None:
            end_local = np.swapaxes(upper_world @ middle_local, -1, -2) @ target.rotation
            if hinge is not KNEE_HINGE:
                # A wrist cannot twist; the forearm turns the hand (pronation/supination), so
                # the end rotation's twist about the forearm moves into the middle joint.
                twist = twist_about(end_local, sk.offsets[e])
                middle_local = middle_local @ twist
                end_local = np.swapaxes(twist, -1, -2) @ end_local
            local[:, e] = end_local
        local[:, u], local[:, m] = upper_local, middle_local
    return local
