"""Exact MuJoCo ``qpos`` of a motion on the body's own skeleton.

qpos = root position (3), root quaternion wxyz (4), then per simulated joint in body order
its hinge angles: the intrinsic Euler angles of the joint's local rotation in the order its
hinges are declared (``R = R_a R_b R_c``). Angles are unwrapped over time, so a joint turning
past +-pi keeps a continuous trajectory. Fixed joints (fingers, toe tips, jaw...) are dropped.
"""

from __future__ import annotations

import numpy as np

from avatar_models import quat
from avatar_models.body.description import BodyDescription
from avatar_models.body.errors import BodyError
from avatar_models.motion import Motion


def qpos_from_motion(desc: BodyDescription, motion: Motion) -> np.ndarray:
    """``(T, 7 + 3 * hinge joints)`` qpos for ``motion`` (which must be on ``desc``'s
    skeleton, same joint names and parents). The root position is used as given: on a body
    scaled away from the motion's skeleton the angles carry over, the positions do not."""
    if not motion.skeleton.same_topology(desc.skeleton):
        raise BodyError(
            f"motion skeleton {motion.skeleton!r} is not the body's skeleton {desc.skeleton!r}"
        )
    columns = [motion.root_pos, quat.normalize(motion.local_rot[:, 0])]
    for j in desc.body_order[1:]:
        angles = quat.to_scipy(motion.local_rot[:, j]).as_euler(desc.hinge_order(j))
        columns.append(np.unwrap(angles, axis=0))
    return np.concatenate(columns, axis=1)
