"""AvatarGo's per-tick IK: closed-form two-bone IK in place of the paper's Unity IK (§3.4).

§3.4 drives the avatar with Unity's built-in IK: end effectors at the wrists and ankles
(analytic two-bone limbs), the root placed from the back tracker (eqs. 2-3), the spine
inclined by forward kinematics by ``alpha_t = angle(w0, w_t)`` (eq. 4) and the head turned
as the headset. :class:`AnalyticIK` is that structure on the avatar's skeleton, each tick:

1. **root**: the pelvis joint at its goal position and rotation (eqs. 2-3 of the back
   tracker); the skeleton's root carries it (the joints between them keep their rest);
2. **spine**: eq. 4's bend (:func:`~synthesis.avatargo.spine.spine_bend_in_root`, measured
   from the spine joint to the head's centre, see :mod:`synthesis.avatargo.spine`) applied
   to "the spine joint" (§3.4), the first above the pelvis; the rest of the back and the
   neck keep their rest, so the upper body turns rigidly about it. Built-in study (30 users,
   realistic noise), mean head error: 3.5 cm with the bend spread evenly over the avatar
   rig's three spine joints and ``w`` between the devices, 1.8 cm on the one joint with
   ``w`` from the root joint, 0.63 cm as here;
3. **head**: its rotation from the headset through its exact offset; its position follows
   by forward kinematics (it is not a goal of Unity's IK either), on the line from the
   spine joint to its goal;
4. **legs and arms**: two-bone IK (:func:`synthesis.two_bone.solve`) of hip-knee-ankle onto
   the ankle's goal (eq. 2) and of shoulder-elbow-wrist onto the wrist's goal under the
   controller (:mod:`synthesis.avatargo.hands`): each middle joint pre-bent from the T-pose
   about its hinge (the shank backwards, the forearm forwards, :data:`BEND_TOWARD`), the
   law of cosines, the limb swung onto its goal; then, as the hint (pole) of Unity's
   TwoBoneIK, the limb turned about its upper-to-end line until the knee points where the
   foot's goal points and the elbow where it would be with the wrist straight (the hand's
   goal rotation carrying the forearm; down and back, :data:`ELBOW_POLES`, for an arm
   straight in it). The elbow's pole from the hand keeps the wrist within its range
   (built-in boxing, 4 users: frames with a joint out of the humanoid's range 0.59 / 0.65 /
   0.01 / 0.08 with no pole, 0.19 / 0.11 / 0 / 0.15 with it);
5. **ankles and wrists**: their rotations set to their goals (eq. 3; the controller's
   rotation through the palm offset), so the palm sits on the controller wherever the
   wrist reaches its goal.

Joint ranges: the knees' and elbows' flexion stays within the humanoid's hinge range
(:func:`flexion_limit`; a goal nearer than that bend allows leaves the end short of it),
and a goal beyond the limb's length leaves the limb straight, pointing at it (the hand is
then reported out of reach, :func:`~synthesis.avatargo.hands.out_of_reach`). Hips,
shoulders, spine, head, ankles and wrists are not limited: their rotations are the user's
own (trackers, eq. 3), within the user's range; where an avatar of other proportions puts
one out of the humanoid's range, the physics check (``joint_limit_violation_frac``) shows it,
as it would of Unity's IK.

Per tick this is a fixed, small amount of numpy on ``(B, 4, ...)`` arrays, vectorised over
the ``B`` frames of a batch (nothing carries over between frames) and over the four limbs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import mujoco
import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body import BodyDescription
from avatarsim.synthesis.two_bone import solve as two_bone

LIMBS = (
    ("l_hip", "l_knee", "l_ankle"),
    ("r_hip", "r_knee", "r_ankle"),
    ("l_shoulder", "l_elbow", "l_wrist"),
    ("r_shoulder", "r_elbow", "r_wrist"),
)
"""The four two-bone limbs (body17 joints: upper, middle, end), legs first."""
LEGS = 2
BEND_TOWARD = np.array([[-1.0, 0.0, 0.0]] * 2 + [[1.0, 0.0, 0.0]] * 2)
"""``(4, 3)`` where each middle joint's lower bone turns when it flexes, in the rest frame
(facing +X): the shank backwards, the forearm forwards. The hinge is the lower bone crossed
with it (:meth:`AnalyticIK.hinges`)."""
ELBOW_POLES = np.array([[-0.3, 0.3, -1.0], [-0.3, -0.3, -1.0]])
"""``(2, 3)`` where the elbows point (Unity's TwoBoneIK hint) for an arm straight in its hand's
goal, left and right, in the shoulders' parents' frame (the chest's; facing +X, left +Y):
down, a little back and out (our choice)."""
POLE_NUDGE_M = 0.05
"""How far the default pole pulls the middle joint's aim (our choice: a few cm, less than a
bent limb's offset from its line, more than a straight one's)."""
PRE_BEND_RAD = 0.2
"""The pre-bend that gives each straight rest limb its bend plane; the two-bone solve then
sets the bend itself (any angle well away from 0 and pi gives the same result)."""


class AnalyticGoals(NamedTuple):
    """The goals of ``B`` frames (world frame, wxyz unit quaternions), in the argument order
    of :meth:`AnalyticIK.solve`.

    Attributes:
        pelvis_pos, pelvis_rot: ``(B, 3)``, ``(B, 4)`` the pelvis joint (eqs. 2-3).
        spine_bend: ``(B, 4)`` the whole spine's bend in the pelvis frame (eq. 4).
        head_rot: ``(B, 4)`` the head joint's world rotation.
        end_pos, end_rot: ``(B, 4, 3)``, ``(B, 4, 4)`` ankles' and wrists' goals
            (:data:`LIMBS` order).
    """

    pelvis_pos: np.ndarray
    pelvis_rot: np.ndarray
    spine_bend: np.ndarray
    head_rot: np.ndarray
    end_pos: np.ndarray
    end_rot: np.ndarray


@dataclass(frozen=True, eq=False)
class AnalyticPose:
    """One batch solved by :meth:`AnalyticIK.solve`.

    Attributes:
        root_pos: ``(B, 3)`` the skeleton's root joint, world metres.
        local_rot: ``(B, J, 4)`` wxyz local rotations of the skeleton's joints.
        upper_pos: ``(B, 4, 3)`` hips and shoulders (:data:`LIMBS` order).
        end_pos: ``(B, 4, 3)`` where ankles and wrists ended (their goals where reachable).
        end_mat: ``(B, 4, 3, 3)`` their world rotations (the goals'), as matrices.
        goal_dist: ``(B, 4)`` metres from the hips and shoulders to the ends' goals.
    """

    root_pos: np.ndarray
    local_rot: np.ndarray
    upper_pos: np.ndarray
    end_pos: np.ndarray
    end_mat: np.ndarray
    goal_dist: np.ndarray


def path_between(parents, ancestor: int, joint: int) -> list[int]:
    """Joints from ``ancestor`` (excluded) down to ``joint`` (included)."""
    path = []
    while joint != ancestor:
        if joint < 0:
            raise ValueError(f"joint {joint} is not below {ancestor}")
        path.append(joint)
        joint = parents[joint]
    return path[::-1]


def flexion_limit(model: mujoco.MjModel, body: str, hinge: np.ndarray) -> float:
    """Largest flexion (radians) about ``hinge (3,)`` (rest frame) that the humanoid's hinge
    joints of ``body`` allow: the range end of the hinge most parallel to it, on its side;
    pi where the body has no limited hinge about that axis."""
    body_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    joints = np.flatnonzero(
        (model.jnt_bodyid == body_id)
        & (model.jnt_type == mujoco.mjtJoint.mjJNT_HINGE)
        & model.jnt_limited.astype(bool)
    )
    if body_id < 0 or joints.size == 0:
        return np.pi
    along = model.jnt_axis[joints] @ hinge
    k = int(np.argmax(np.abs(along)))
    if abs(along[k]) < 0.9:  # no hinge about this axis
        return np.pi
    low, high = model.jnt_range[joints[k]]
    return float(high if along[k] > 0 else -low)


class AnalyticIK:
    """Closed-form two-bone IK in place of the paper's Unity IK, on ``body``'s skeleton
    (module docstring).

    The skeleton's rest pose must be the avatar's T-pose facing +X (the walk-in pose, as
    every rig :func:`~avatar_models.body.build_body` accepts), with the pelvis, spine, neck,
    head and limbs of its body17 map on one chain each.
    """

    def __init__(self, body: BodyDescription):
        sk, body17 = body.skeleton, body.rig.body17
        parents = np.asarray(sk.parents)
        rest = sk.rest_positions()
        self.pelvis = sk.index(body17["pelvis"])
        neck, head = sk.index(body17["neck"]), sk.index(body17["head"])
        self.head = head
        self.spine = path_between(parents, self.pelvis, neck)[0]  # "the spine joint" (§3.4)
        self.root_to_pelvis = rest[self.pelvis] - rest[0]
        anchors = [0, self.spine]  # the joints whose rotation the spine's bend sets
        self.root_to_spine = rest[self.spine] - rest[0]
        self.pelvis_to_spine = rest[self.spine] - rest[self.pelvis]
        """``(3,)`` the spine joint from the pelvis, in the pelvis's frame."""
        self.spine_to_head = rest[head] - rest[self.spine]
        """``(3,)`` the head from the spine joint, in the pelvis's frame at the walk-in (eq. 1's
        ``w0`` as :mod:`synthesis.avatargo.spine` measures it)."""
        limbs = np.array([[sk.index(body17[j]) for j in limb] for limb in LIMBS])  # (4, 3)
        self.limbs = limbs

        def anchor_of(joint: int) -> int:
            """Index in ``anchors`` of the nearest strict ancestor of ``joint`` there."""
            j = parents[joint]
            while j not in anchors:
                j = parents[j]
            return anchors.index(j)

        self.upper_anchor = np.array([anchor_of(j) for j in limbs[:, 0]])
        self.head_anchor = anchor_of(head)
        self.upper_offsets = rest[limbs[:, 0]] - rest[np.array(anchors)[self.upper_anchor]]
        self.upper_bones = rest[limbs[:, 1]] - rest[limbs[:, 0]]  # (4, 3)
        self.lower_bones = rest[limbs[:, 2]] - rest[limbs[:, 1]]
        self.hinges = quat.cross(self.lower_bones, BEND_TOWARD)
        self.hinges /= np.linalg.norm(self.hinges, axis=-1, keepdims=True)
        self.pre_bend = quat.from_axis_angle(self.hinges, np.full(len(LIMBS), PRE_BEND_RAD))
        self.elbow_poles = ELBOW_POLES / np.linalg.norm(ELBOW_POLES, axis=-1, keepdims=True)
        poles = np.concatenate([np.zeros((LEGS, 3)), self.elbow_poles])  # knees: none
        self.rest_vectors = np.stack(
            [self.upper_offsets, self.upper_bones, self.lower_bones, poles], axis=1
        )
        """``(4, 4, 3)`` per limb: the upper joint from its anchor, the upper and lower bones,
        the elbow's pole (the knees': 0), each in the rest frame of :attr:`frame_index`'s."""
        middle = 2 + np.arange(len(LIMBS))  # the middle joints' rows of solve's matrices
        self.frame_index = np.stack(
            [self.upper_anchor, self.upper_anchor, middle, self.upper_anchor], axis=1
        )
        """``(4, 4)`` rows of :meth:`solve`'s world matrices (root, spine joint, the four
        middle joints, ...) that turn :attr:`rest_vectors`: the anchor's, the anchor's, the
        middle joint's, the anchor's."""
        self._root_columns = np.stack([self.root_to_pelvis, self.root_to_spine], axis=-1)
        l1 = np.linalg.norm(self.upper_bones, axis=-1)
        l2 = np.linalg.norm(self.lower_bones, axis=-1)
        knees_elbows = zip(limbs[:, 1], self.hinges, strict=True)
        flexion = np.array([flexion_limit(body.model, sk.names[j], h) for j, h in knees_elbows])
        # The nearest reach: the law of cosines at the largest flexion (straight limbs at
        # rest: the flexion is the angle between the bones).
        self.reach = np.stack(
            [np.sqrt(l1**2 + l2**2 + 2 * l1 * l2 * np.cos(flexion)), l1 + l2], axis=-1
        )  # (4, 2) nearest, farthest
        template = np.tile(quat.IDENTITY, (sk.n_joints, 1))
        template[limbs[:, 1]] = self.pre_bend
        self.template = template

    @property
    def arm_length(self) -> np.ndarray:
        """``(2,)`` shoulder to wrist, left and right arm, straight."""
        return self.reach[LEGS:, 1]

    def solve(
        self,
        pelvis_pos: np.ndarray,
        pelvis_rot: np.ndarray,
        spine_bend: np.ndarray,
        head_rot: np.ndarray,
        end_pos: np.ndarray,
        end_rot: np.ndarray,
    ) -> AnalyticPose:
        """The pose of ``B`` frames from their goals (:class:`AnalyticGoals`)."""
        b = pelvis_pos.shape[0]
        # The world rotations and positions of the root and the spine joint ("anchors":
        # every other joint hangs from one of them unrotated), as quaternions for the
        # outputs and as matrices for the positions (one matrix product each; numpy's
        # per-call overhead, not the arithmetic, is the cost of these few vectors).
        # (Stacks by np.concatenate of views: np.stack's Python set-up costs more than a
        # tick's few vectors; likewise x.take(index, axis) for x[:, index].)
        spine_rot = quat.mul(pelvis_rot, spine_bend)
        glob = np.concatenate([pelvis_rot[:, None], spine_rot[:, None]], axis=1)  # (B, 2, 4)
        parent = glob.take(self.upper_anchor, axis=1)  # (B, 4, 4) hips' and shoulders' parents
        # One matrix conversion for the anchors, the rest limbs' middle joints pre-bent about
        # their hinges (the bend planes) and the ends' goals.
        middle_rot = quat.mul(parent, self.pre_bend)
        mats = quat.unit_to_matrix(np.concatenate([glob, middle_rot, end_rot], axis=1))
        end_mat = mats[:, 2 + len(LIMBS) :]  # (B, 4, 3, 3)
        from_root = mats[:, 0] @ self._root_columns  # (B, 3, 2) to the pelvis, to the spine
        root_pos = pelvis_pos - from_root[..., 0]
        spine_pos = root_pos + from_root[..., 1]
        pos = np.concatenate([root_pos[:, None], spine_pos[:, None]], axis=1)

        local = self.template[None].repeat(b, axis=0)
        local[:, 0] = pelvis_rot
        local[:, self.spine] = spine_bend
        local[:, self.head] = quat.mul(quat.conj(glob[:, self.head_anchor]), head_rot)

        # Each limb's rest vectors (:attr:`rest_vectors`) turned by their frames, in one
        # product; the chain's positions are their running sum from the anchor (cumsum adds
        # in the order a loop would). The first three frames are the two-bone solve's (it
        # reads neither the fourth nor the first position, the anchor's).
        globs = mats.take(self.frame_index, axis=1)  # (B, 4, 4, 3, 3)
        steps = (globs @ self.rest_vectors[..., None])[..., 0]  # (B, 4, 4, 3)
        anchor = pos.take(self.upper_anchor, axis=1)[:, :, None]
        chain_pos = np.concatenate([anchor, steps[:, :, :3]], axis=2).cumsum(axis=2)
        upper_pos = chain_pos[:, :, 1]  # (B, 4, 3)
        # Goals nearer than the flexion limit or beyond the limb's length: the reachable
        # point on the way to the goal.
        # (np.linalg.norm's and np.clip's arithmetic without their Python wrappers, whose
        # set-up costs more than a tick's few vectors; likewise np.add.reduce for np.sum.)
        reach = end_pos - upper_pos
        dist = np.sqrt(np.add.reduce(reach * reach, axis=-1, keepdims=True))
        clipped = np.minimum(np.maximum(dist, self.reach[:, :1]), self.reach[:, 1:])
        target = upper_pos + reach * (clipped / np.maximum(dist, 1e-12))
        local = two_bone(local, globs, chain_pos, self.limbs, target)
        # The pole (Unity's hint): each limb turned about its upper-to-end line until the
        # knee or elbow points as near as it can to it.
        limb = self.limbs
        upper = quat.mul(parent, local.take(limb[:, 0], axis=1))
        bent = (quat.unit_to_matrix(upper) @ self.upper_bones[..., None])[..., 0]
        # Knees: where the feet point (their goals' +X). Elbows: where the elbow would be
        # with the wrist straight (the hand's goal rotation carrying the forearm), nudged
        # towards down and back for an arm straight in the hand's goal (that point then
        # lies on the line).
        elbows = steps[:, LEGS:, 3]  # (B, 2, 3)
        straight = (end_mat[:, LEGS:] @ self.lower_bones[LEGS:, :, None])[..., 0]
        straight = target[:, LEGS:] - straight - upper_pos[:, LEGS:]
        pole = np.concatenate([end_mat[:, :LEGS, :, 0], straight + POLE_NUDGE_M * elbows], 1)
        axis = target - upper_pos
        axis /= np.sqrt(np.add.reduce(axis * axis, axis=-1, keepdims=True))
        both = np.concatenate([bent[:, :, None], pole[:, :, None]], axis=2)  # (B, 4, 2, 3)
        along = axis[:, :, None]
        both = both - np.add.reduce(both * along, -1, keepdims=True) * along  # across the line
        bent, pole = both[:, :, 0], both[:, :, 1]
        swivel = np.arctan2(
            np.add.reduce(quat.cross(bent, pole) * axis, -1), np.add.reduce(bent * pole, -1)
        )
        turn = quat.from_axis_angle(axis, swivel)  # (B, 4, 4); a limb along its pole: ~0
        upper = quat.mul(turn, upper)
        # The upper joints' local rotations and the middle joints' world ones in one product.
        upper_middle = quat.mul(
            np.concatenate([quat.conj(parent), upper], axis=1),
            np.concatenate([upper, local.take(limb[:, 1], axis=1)], axis=1),
        )
        local[:, limb[:, 0]] = upper_middle[:, : len(LIMBS)]
        local[:, limb[:, 2]] = quat.mul(quat.conj(upper_middle[:, len(LIMBS) :]), end_rot)
        return AnalyticPose(root_pos, local, upper_pos, target, end_mat, dist[..., 0])
