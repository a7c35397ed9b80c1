"""Spine bend from the headset and the back tracker (AvatarGo §3.3 eq. 1, §3.4 eq. 4).

At the walk-in T-pose AvatarGo stores ``w0 = p0(T_head) - p0(T_root)`` (eq. 1), the vector
from the back tracker to the headset. At run time the back bends by
``alpha_t = angle(w0, w_t)`` (eq. 4), about the axis ``w0 x w_t`` that turns one into the
other, applied to the spine by forward kinematics: :func:`spine_bend`.

The analytic IK (:mod:`synthesis.avatargo.analytic_ik`) turns "the spine joint" (§3.4) by
``alpha_t``, so it measures eq. 1 and eq. 4 from that joint, the pivot of the bend, to
"the center of the head" (eq. 1's text): the head joint under the headset and the spine
joint on the pelvis, each carried from its device by the exact offsets (eqs. 2-3). The head
then lands on the line from the pivot to its goal, off only by how much the user's back
shortens as it curves. Our choice; the literal readings put the head off (built-in
motion, 2 s, avatar = user, no noise, mean head error on wave / box / walk): from the
devices' own positions (the headset ~10 cm in front of the head's centre, so that a turn
of the chest reads as a sideways lean) 0.56 / 2.3 cm on wave / box; from the root joint
0.27 / 0.86 / 0.15 cm; from the spine joint 0.005 / 0.04 / 0.004 cm. The root also turns with the
back tracker (eq. 3) and the spine hangs from it, so eq. 4 is measured in the root's frame
(:func:`spine_bend_in_root`): a turn or lean of the whole body is the root's rotation, not
counted a second time as a bend. With the root's rotation unchanged since the walk-in it is
eq. 4's rotation exactly. The QP solvers use :func:`spine_bend` on the devices' ``w0`` in
the world frame, turning the rest pelvis-to-neck vector into a soft target for the neck.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.synthesis.two_bone import unit


def bend_angle(w0: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``alpha_t (B,)`` radians between ``w0 (3,)`` and ``w (B, 3)`` (eq. 4)."""
    cross = np.linalg.norm(np.cross(w0, w), axis=-1)
    return np.arctan2(cross, w @ w0)


def spine_bend(w0: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``(B, 4)`` wxyz rotations by ``alpha_t`` about ``w0 x w_t`` (identity where parallel):
    each turns the direction of ``w0 (3,)`` onto that of ``w (B, 3)``, the shortest arc."""
    return quat.shortest_arc(w0, w)  # broadcasts


def spine_bend_in_root(w0_in_root: np.ndarray, w: np.ndarray, root_mat: np.ndarray) -> np.ndarray:
    """``(B, 4)`` eq. 4's bend in the root joint's frame: ``w0_in_root (3,)``, the direction
    of eq. 1's ``w0`` seen from the root's walk-in rotation (``R0(root)^-1 w0``, normalised
    by :func:`~synthesis.two_bone.unit`: the caller keeps it from tick to tick), turned onto
    ``w (B, 3)`` seen from the root's rotations, as matrices ``root_mat (B, 3, 3)`` (module
    docstring; the caller has them already, a tick's hot path)."""
    # R^T w by a matrix product: fewer numpy calls than quat.rotate on a tick's vectors.
    w_in_root = (np.asarray(w)[..., None, :] @ root_mat)[..., 0, :]
    return quat.unit_arc(w0_in_root, unit(w_in_root)[0])
