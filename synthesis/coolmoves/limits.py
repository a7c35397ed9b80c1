"""Joint-angle limits: "we further threshold the joint angles to constrain the degree-of-freedom
for each joint based on human motion dynamics" (CoolMoves §3.1.4).

The limits are the rig's own (``Skeleton.limits``: ``rx, ry, rz`` ranges about the joint's
local axes; the avatar rig carries the AAOS ranges of motion). A joint's rotation is split
into intrinsic Euler angles in the order of its anatomical role
(:mod:`avatar_models.body.joint_ranges`: e.g. ``YXZ`` for legs and spine, so that flexion
comes first), each angle is clipped to its range, and the rotation rebuilt. Joints without a
recognised role use ``XYZ``.

Stylised databases go beyond textbook ranges (a boxer's guard, a swimmer's stroke), and near
an Euler singularity a small pose change swings the angles widely: clipping those would
distort the very poses the database holds. Given the database poses (``widen_to``), each
range is therefore widened to include every angle they reach, so that only blends leaving
both the anatomical and the recorded range are thresholded.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from avatar_models import Skeleton
from avatar_models.body.anatomy import classify
from avatar_models.body.joint_ranges import euler_order
from avatar_models.rigs import RigError, identify_rig

_DEFAULT_ORDER = "XYZ"


class JointLimits:
    """Clamp local rotations to a skeleton's joint limits, vectorised per Euler order."""

    def __init__(self, skeleton: Skeleton, widen_to: np.ndarray | None = None):
        """``widen_to``: optional ``(P, J, 4)`` poses whose angles every range must include."""
        try:
            rig = identify_rig(skeleton)
            roles = classify(skeleton, rig).roles
        except RigError:
            roles = {}
        groups: dict[str, list[int]] = {}
        for name in skeleton.limits:
            j = skeleton.index(name)
            role = roles.get(j)
            order = euler_order(role) if role not in (None, "root") else _DEFAULT_ORDER
            groups.setdefault(order, []).append(j)
        self.groups: list[tuple[str, np.ndarray, np.ndarray, np.ndarray]] = []
        for order, joints in groups.items():
            bounds = np.array(
                [
                    [
                        skeleton.limits[skeleton.names[j]].get(f"r{a.lower()}", (-np.pi, np.pi))
                        for a in order
                    ]
                    for j in joints
                ]
            )  # (G, 3 axes, lo/hi)
            lo, hi = bounds[..., 0], bounds[..., 1]
            if widen_to is not None and len(widen_to):
                angles = _euler(np.asarray(widen_to)[:, joints], order)  # (P, G, 3)
                lo, hi = np.minimum(lo, angles.min(axis=0)), np.maximum(hi, angles.max(axis=0))
            self.groups.append((order, np.array(joints), lo, hi))

    def clamp(self, local_rot: np.ndarray) -> np.ndarray:
        """``local_rot (..., J, 4)`` wxyz with every limited joint inside its ranges."""
        out = np.array(local_rot, dtype=float)
        for order, joints, lo, hi in self.groups:
            q = out[..., joints, :]
            angles = _euler(q, order)
            clipped = np.clip(angles, lo, hi)
            changed = np.any(clipped != angles, axis=-1)
            if not np.any(changed):
                continue
            xyzw = Rotation.from_euler(order, clipped.reshape(-1, 3)).as_quat()
            rebuilt = xyzw[:, [3, 0, 1, 2]].reshape(q.shape)
            out[..., joints, :] = np.where(changed[..., None], rebuilt, q)
        return out


def _euler(q: np.ndarray, order: str) -> np.ndarray:
    """``(..., 4)`` wxyz -> ``(..., 3)`` intrinsic Euler angles in ``order``."""
    angles = Rotation.from_quat(q.reshape(-1, 4)[:, [1, 2, 3, 0]]).as_euler(order)
    return angles.reshape(*q.shape[:-1], 3)
