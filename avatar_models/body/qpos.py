"""Exact MuJoCo ``qpos`` of a motion on the body's own skeleton.

qpos = root position (3), root quaternion wxyz (4), then per simulated joint in body order
its hinge angles: the intrinsic Euler angles of the joint's local rotation in the order its
hinges are declared (``R = R_a R_b R_c``). Angles are unwrapped over time, so a joint turning
past +-pi keeps a continuous trajectory. Fixed joints (fingers, toe tips, jaw...) are dropped.

Forearm rotation (pronation/supination) belongs to the forearm: a wrist does not twist (its
axial hinge is only a small allowance, see :mod:`~avatar_models.body.joint_ranges`), but
rigs differ in where they put it. CMU (ASF ``rwrist``, cgspeed ``RightHand``) carries it as
the wrist joint's single degree of freedom, about the forearm's long axis. So the twist of
each wrist's local rotation about its bone (the forearm, elbow to wrist) is moved into the
elbow: ``R_elbow R_wrist = (R_elbow T)(T^-1 R_wrist)``. Every joint position and the hand's
orientation are unchanged; only the forearm capsule turns about its own axis.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body.description import BodyDescription
from avatarsim.avatar_models.body.errors import BodyError
from avatarsim.avatar_models.motion import Motion


def _forearm_takes_wrist_twist(desc: BodyDescription, local_rot: np.ndarray) -> np.ndarray:
    """``local_rot (T, J, 4)`` with each wrist's twist about its bone moved into its elbow."""
    roles, parents = desc.anatomy.roles, desc.skeleton.parents
    out = local_rot
    for j, role in roles.items():
        e = int(parents[j]) if j else -1
        if role != "wrist" or roles.get(e) != "elbow":
            continue
        bone = np.asarray(desc.skeleton.offsets[j], dtype=float)
        if np.linalg.norm(bone) < 1e-9:
            continue
        axis = bone / np.linalg.norm(bone)
        q = local_rot[:, j]
        angle = 2.0 * np.arctan2(q[:, 1:] @ axis, q[:, 0])  # swing-twist: twist about axis
        twist = quat.from_axis_angle(axis, angle)
        if out is local_rot:
            out = local_rot.copy()
        out[:, e] = quat.mul(out[:, e], twist)
        out[:, j] = quat.mul(quat.conj(twist), q)
    return out


def qpos_from_motion(desc: BodyDescription, motion: Motion) -> np.ndarray:
    """``(T, 7 + 3 * hinge joints)`` qpos for ``motion`` (which must be on ``desc``'s
    skeleton, same joint names and parents). The root position is used as given: on a body
    scaled away from the motion's skeleton the angles carry over, the positions do not."""
    if not motion.skeleton.same_topology(desc.skeleton):
        raise BodyError(
            f"motion skeleton {motion.skeleton!r} is not the body's skeleton {desc.skeleton!r}"
        )
    local_rot = _forearm_takes_wrist_twist(desc, motion.local_rot)
    columns = [motion.root_pos, quat.normalize(motion.local_rot[:, 0])]
    for j in desc.body_order[1:]:
        angles = quat.to_scipy(local_rot[:, j]).as_euler(desc.hinge_order(j))
        columns.append(np.unwrap(angles, axis=0))
    return np.concatenate(columns, axis=1)
