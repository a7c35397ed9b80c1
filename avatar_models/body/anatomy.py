"""Which skeleton joints are simulated, what anatomical role each has, and what each bone is.

Works for any skeleton :func:`avatar_models.rigs.identify_rig` recognises, from its ``body17``
map alone. The simulated joints are the chains from the root to the head, the wrists and the
ankles, plus the toe joint (body17 ``foot``, the ball of the foot) where it is a child of the
ankle; every other joint (fingers, toe tips, jaw, eyelids, twist bones, end sites) is fixed
into its nearest simulated ancestor. A joint's role names the anatomical joint it stands for
(see :mod:`avatar_models.body.joint_ranges`), a bone's kind names the de Leva segment it
belongs to (see :mod:`avatar_models.body.anthropometry`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models.rigs import Rig
from avatarsim.avatar_models.skeleton import Skeleton

# The body17 joints of a limb; each names the role of the joints from it down to the next.
_LIMB_JOINTS = {"leg": ("hip", "knee", "ankle"), "arm": ("shoulder", "elbow", "wrist")}
_GIRDLE = {"leg": "pelvic_girdle", "arm": "shoulder_girdle"}

# Role of a bone's proximal joint -> the segment kind of the bone.
_BONE_KIND = {
    "root_chain": "pelvis",
    "pelvic_girdle": "pelvis",
    "spine": "torso",
    "shoulder_girdle": "torso",
    "hip": "thigh",
    "knee": "shank",
    "ankle": "foot",
    "toe": "foot",
    "shoulder": "upper_arm",
    "elbow": "forearm",
    "wrist": "hand",
}


@dataclass(frozen=True)
class Anatomy:
    """Joint classification of one skeleton.

    Attributes:
        simulated: ``(J,)`` bool, joints that get a MuJoCo body.
        roles: role of each simulated non-root joint (index -> role), the root has ``"root"``.
        sides: ``"left"``, ``"right"`` or ``"center"`` per joint.
        bone_kind: ``(J,)`` segment kind of the bone from each joint's parent to it
            (``""`` for the root).
        body_of: ``(J,)`` index of the simulated joint whose body carries each joint.
        body17: body17 name -> joint index.
    """

    simulated: np.ndarray
    roles: dict[int, str]
    sides: tuple[str, ...]
    bone_kind: tuple[str, ...]
    body_of: np.ndarray
    body17: dict[str, int]


def classify(skeleton: Skeleton, rig: Rig) -> Anatomy:
    """Classify the joints of ``skeleton`` using the ``body17`` map of ``rig``."""
    b = {k: skeleton.index(v) for k, v in rig.body17.items()}
    trunk = skeleton.chain(b["neck"])
    pelvis_chain = set(skeleton.chain(b["pelvis"]))
    head_chain = skeleton.chain(b["head"])
    limb_chains = {
        (side, limb): skeleton.chain(b[f"{side[0]}_{_LIMB_JOINTS[limb][-1]}"])
        for side in ("left", "right")
        for limb in ("leg", "arm")
    }
    roles: dict[int, str] = {0: "root"}
    sides = ["center"] * skeleton.n_joints
    for j in trunk + head_chain:
        if j == 0:
            continue
        if j in pelvis_chain:
            roles[j] = "root_chain"
        elif j in trunk and j != b["neck"]:
            roles[j] = "spine"
        else:
            roles[j] = "cervical"
    arm_path: set[int] = set()
    for (side, limb), chain in limb_chains.items():
        role = _GIRDLE[limb]
        marks = {b[f"{side[0]}_{name}"]: name for name in _LIMB_JOINTS[limb]}
        for j in chain:
            if j in roles and j not in marks:
                continue
            role = marks.get(j, role)
            roles[j] = role
            sides[j] = side
            if limb == "arm":
                arm_path.add(j)
        # The ball of the foot bends in gait (heel rise, push-off), so the toes get their own
        # body when the rig has the toe joint straight below the ankle.
        if limb == "leg" and skeleton.parents[b[f"{side[0]}_foot"]] == b[f"{side[0]}_ankle"]:
            roles[b[f"{side[0]}_foot"]] = "toe"
            sides[b[f"{side[0]}_foot"]] = side
    simulated = np.zeros(skeleton.n_joints, bool)
    simulated[list(roles)] = True

    bone_kind = [""] * skeleton.n_joints
    body_of = np.arange(skeleton.n_joints)
    for c in range(1, skeleton.n_joints):
        p = int(skeleton.parents[c])
        if not simulated[c]:
            body_of[c] = body_of[p]
            sides[c] = sides[p]
        if not simulated[p]:
            bone_kind[c] = bone_kind[p]
        elif roles[p] == "cervical":
            bone_kind[c] = "torso" if c in arm_path else "head"
        elif roles[p] in ("root", "root_chain") and c in trunk:
            bone_kind[c] = "torso"
        else:
            bone_kind[c] = _BONE_KIND.get(roles[p], "pelvis")
    return Anatomy(simulated, roles, tuple(sides), tuple(bone_kind), body_of, b)
