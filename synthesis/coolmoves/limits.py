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

from avatarsim.avatar_models import Skeleton
from avatarsim.avatar_models.body.anatomy import classify
from avatarsim.avatar_models.body.joint_ranges import euler_order
from avatarsim.avatar_models.quat import euler_axes, euler_key, from_euler, to_euler
from avatarsim.avatar_models.rigs import RigError, identify_rig

_DEFAULT_ORDER = "XYZ"


class JointLimits:
    """Clamp local rotations to a skeleton's joint limits, all joints in one vectorised pass."""

    def __init__(
        self,
        skeleton: Skeleton,
        widen_to: np.ndarray | None = None,
        only: set[int] | None = None,
    ):
        """``widen_to``: optional ``(P, J, 4)`` poses whose angles every range must include;
        ``only``: limit just these joint indices (default: every joint with limits)."""
        try:
            rig = identify_rig(skeleton)
            roles = classify(skeleton, rig).roles
        except RigError:
            roles = {}
        joints, orders, pairs = [], [], []
        for name in skeleton.limits:
            j = skeleton.index(name)
            if only is not None and j not in only:
                continue
            role = roles.get(j)
            joints.append(j)
            orders.append(euler_order(role) if role not in (None, "root") else _DEFAULT_ORDER)
            pairs.append((skeleton.limits[name], orders[-1]))
        # All limited joints at once, each with its own Euler order: one pass per call.
        self.joints = np.array(joints, dtype=np.int64)
        self.axes = euler_axes(orders) if joints else np.zeros((0, 3), np.int64)
        bounds = np.array(
            [[r.get(f"r{a.lower()}", (-np.pi, np.pi)) for a in order] for r, order in pairs]
        ).reshape(len(joints), 3, 2)  # (G, 3 axes, lo/hi)
        self.lo, self.hi = bounds[..., 0], bounds[..., 1]
        self._orders = euler_key(self.axes)  # converted once, not on every clamp
        if widen_to is not None and len(widen_to) and joints:
            angles = to_euler(np.asarray(widen_to)[:, self.joints], self.axes)  # (P, G, 3)
            self.lo = np.minimum(self.lo, angles.min(axis=0))
            self.hi = np.maximum(self.hi, angles.max(axis=0))

    def clamp(self, local_rot: np.ndarray) -> np.ndarray:
        """``local_rot (..., J, 4)`` wxyz with every limited joint inside its ranges."""
        out = np.array(local_rot, dtype=float)
        if not self.joints.size:
            return out
        q = out[..., self.joints, :]
        angles = to_euler(q, self._orders)
        clipped = np.minimum(np.maximum(angles, self.lo), self.hi)  # np.clip's numbers
        changed = np.logical_or.reduce(clipped != angles, axis=-1)
        if changed.any():
            out[..., self.joints, :] = np.where(
                changed[..., None], from_euler(clipped, self._orders), q
            )
        return out
