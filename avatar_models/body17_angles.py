"""ControllerPose's joint-angle parameterisation of ``body17``: 43 DoF, hip as root.

ControllerPose §4.3: "3D joint angles for the aforementioned 17 keypoints with respect to
their parent (hip is the root) with 43 degrees of freedom". The paper gives no table; this
is the reading used by the dataset labels and the network (one source for both).

Tree (paper names -> :data:`~avatar_models.body17.BODY17`: mid hip = ``pelvis``, torso =
``neck``, pelvis L/R = ``l_hip``/``r_hip``, hand = ``wrist``)::

    pelvis -> neck -> head
              neck -> {l,r}_shoulder -> {l,r}_elbow -> {l,r}_wrist
    pelvis -> {l,r}_hip -> {l,r}_knee -> {l,r}_ankle -> {l,r}_foot

Every keypoint but the root ends one bone (from its parent). Bone ``k`` has a world frame
``R_k = R_parent(k) @ L_k`` and lies along it: ``x_k = x_parent(k) + length_k R_k d_k``, with
the rest direction ``d_k`` (:data:`REST_DIRECTIONS`; all ``L_k = I`` is a pose facing +X,
Z up, arms and legs hanging, feet forward). The root frame is ``R_pelvis`` (x forward, y
towards the left hip, z up the spine) at ``x_pelvis = 0``.

The 43 DoF, in ``BODY17`` order (:data:`DOF_SLICES`): 13 keypoints x 3 + 4 x 1.

- ``pelvis``: the rotation vector of the root frame (3);
- ``wrist`` and ``ankle`` (forearm and shin): 1 each, a hinge about the parent frame's y
  axis (elbow and knee flexion): ``L_k = Ry(angle)``;
- every other keypoint: the rotation vector of ``L_k`` (3).

:func:`angles_from_positions` picks, of the many ``L_k`` that place a bone, the one whose
twist is fixed by a rule: upper arm and thigh twist so that the hinge child lies in their
x-z plane, the forearm on the +x side (elbows bend forward), the shin on the -x side
(knees bend back); every other bone has the smallest rotation (no twist; its twist moves
no keypoint). A nearly straight arm or leg leaves the twist of its upper segment
ill-conditioned (any twist places the keypoints); it is still exact.

Rotation vectors are ``theta * axis`` with ``theta`` in ``[0, pi]``.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body17 import BODY17, INDEX

PARENT_NAMES: dict[str, str] = {
    "neck": "pelvis",
    "head": "neck",
    "l_shoulder": "neck",
    "r_shoulder": "neck",
    "l_elbow": "l_shoulder",
    "r_elbow": "r_shoulder",
    "l_wrist": "l_elbow",
    "r_wrist": "r_elbow",
    "l_hip": "pelvis",
    "r_hip": "pelvis",
    "l_knee": "l_hip",
    "r_knee": "r_hip",
    "l_ankle": "l_knee",
    "r_ankle": "r_knee",
    "l_foot": "l_ankle",
    "r_foot": "r_ankle",
}
ROOT = INDEX["pelvis"]
PARENTS = np.array([INDEX.get(PARENT_NAMES.get(n, ""), -1) for n in BODY17])
"""``(17,)`` parent of each keypoint (root -1)."""

# Parents before children: the order forward kinematics visits the keypoints in.
FK_ORDER = np.array(
    [ROOT, INDEX["neck"], INDEX["head"]] + [INDEX[n] for n in BODY17 if n.startswith(("l_", "r_"))]
)

UP, DOWN, LEFT, FORWARD = (0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)
REST_DIRECTIONS = np.array(
    [
        {
            "head": UP,
            "neck": UP,
            "pelvis": (0.0, 0.0, 0.0),
            "l_shoulder": LEFT,
            "r_shoulder": (0.0, -1.0, 0.0),
            "l_hip": LEFT,
            "r_hip": (0.0, -1.0, 0.0),
            "l_foot": FORWARD,
            "r_foot": FORWARD,
        }.get(n, DOWN)
        for n in BODY17
    ]
)
"""``(17, 3)`` bone direction in its own frame (unit; the root has no bone)."""

HINGES = (INDEX["l_wrist"], INDEX["r_wrist"], INDEX["l_ankle"], INDEX["r_ankle"])
# Which side of its parent's x-z plane a hinge child lies on: +1 forward (elbows), -1 back
# (knees); see the module docstring.
HINGE_SIDE = {INDEX["l_elbow"]: 1.0, INDEX["r_elbow"]: 1.0, INDEX["l_knee"]: -1.0,
              INDEX["r_knee"]: -1.0}  # fmt: skip

DOF_PER_KEYPOINT = np.array([1 if k in HINGES else 3 for k in range(len(BODY17))])
N_DOF = int(DOF_PER_KEYPOINT.sum())
DOF_SLICES = tuple(
    slice(int(a), int(b))
    for a, b in zip(
        np.cumsum(DOF_PER_KEYPOINT) - DOF_PER_KEYPOINT, np.cumsum(DOF_PER_KEYPOINT), strict=True
    )
)
"""The columns of each keypoint's DoF in a ``(..., 43)`` angle vector, ``BODY17`` order."""


def rotvec_to_matrix(rotvec: np.ndarray) -> np.ndarray:
    """``(..., 3)`` rotation vectors -> ``(..., 3, 3)`` matrices (Rodrigues; exact at 0)."""
    theta2 = np.sum(rotvec * rotvec, axis=-1)[..., None, None]
    theta = np.sqrt(theta2)
    small = theta2 < 1e-12
    safe = np.where(small, 1.0, theta)
    # sin(t)/t and (1 - cos(t))/t^2 with their Taylor series near 0 (no 0/0).
    a = np.where(small, 1.0 - theta2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - theta2 / 24.0, (1.0 - np.cos(safe)) / (safe * safe))
    k = skew(rotvec)
    return np.eye(3) + a * k + b * (k @ k)


def skew(v: np.ndarray) -> np.ndarray:
    """``(..., 3)`` -> ``(..., 3, 3)`` cross-product matrices."""
    zero = np.zeros_like(v[..., 0])
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return np.stack(
        [np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1), np.stack([-y, x, zero], -1)],
        -2,
    )


def matrix_to_rotvec(m: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` rotation matrices -> ``(..., 3)`` rotation vectors, angle in [0, pi]."""
    q = quat.from_matrix(m)
    q = np.where(q[..., :1] < 0.0, -q, q)
    vec_norm = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(vec_norm, q[..., :1])
    scale = np.where(vec_norm > 1e-12, angle / np.maximum(vec_norm, 1e-300), 2.0)
    return q[..., 1:] * scale


def hinge_matrix(angle: np.ndarray) -> np.ndarray:
    """``(...,)`` angles -> ``(..., 3, 3)`` rotations about y."""
    c, s = np.cos(angle), np.sin(angle)
    zero, one = np.zeros_like(angle), np.ones_like(angle)
    return np.stack(
        [np.stack([c, zero, s], -1), np.stack([zero, one, zero], -1), np.stack([-s, zero, c], -1)],
        -2,
    )


def root_frame(positions: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` root frame (columns x forward, y left, z up) of ``(..., 17, 3)``."""
    y = positions[..., INDEX["l_hip"], :] - positions[..., INDEX["r_hip"], :]
    y = y / np.linalg.norm(y, axis=-1, keepdims=True)
    up = positions[..., INDEX["neck"], :] - positions[..., ROOT, :]
    z = up - np.sum(up * y, axis=-1, keepdims=True) * y
    z = z / np.linalg.norm(z, axis=-1, keepdims=True)
    return np.stack([np.cross(y, z), y, z], -1)


def swing(rest: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``(..., 3)`` rotation vectors of the smallest rotations taking unit ``rest`` (3,) to
    unit ``target`` (..., 3)."""
    axis = np.cross(rest, target)
    sin = np.linalg.norm(axis, axis=-1, keepdims=True)
    cos = np.sum(target * rest, axis=-1, keepdims=True)
    angle = np.arctan2(sin, cos)
    # Opposite vectors: any axis perpendicular to rest; take rest x (a non-parallel axis).
    fallback = np.cross(rest, FORWARD if abs(rest[0]) < 0.9 else LEFT)
    axis = np.where(sin > 1e-12, axis / np.maximum(sin, 1e-300), fallback)
    return axis * angle


def angles_from_positions(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 43 DoF and bone lengths of ``positions (..., 17, 3)`` (module docstring).

    Returns:
        ``angles (..., 43)`` radians and ``lengths (..., 17)`` metres (the bone ending at
        each keypoint; 0 at the root), so that :func:`positions_from_angles` gives back
        ``positions - positions[..., pelvis]``.
    """
    positions = np.asarray(positions, dtype=np.float64)
    bones = positions - positions[..., np.maximum(PARENTS, 0), :]
    lengths = np.linalg.norm(bones, axis=-1)
    lengths[..., ROOT] = 0.0
    unit = bones / np.maximum(lengths, 1e-12)[..., None]
    frames = np.broadcast_to(np.eye(3), positions.shape[:-1] + (3, 3)).copy()
    angles = np.zeros(positions.shape[:-2] + (N_DOF,))
    frames[..., ROOT, :, :] = root_frame(positions)
    angles[..., DOF_SLICES[ROOT]] = matrix_to_rotvec(frames[..., ROOT, :, :])
    for k in FK_ORDER[1:]:
        parent = frames[..., PARENTS[k], :, :]
        local_dir = np.einsum("...ji,...j->...i", parent, unit[..., k, :])
        if k in HINGES:
            hinge = np.arctan2(-local_dir[..., 0], -local_dir[..., 2])
            angles[..., DOF_SLICES[k]] = hinge[..., None]
            frames[..., k, :, :] = parent @ hinge_matrix(hinge)
            continue
        local = rotvec_to_matrix(swing(REST_DIRECTIONS[k], local_dir))
        if k in HINGE_SIDE:
            child = int(np.flatnonzero(PARENTS == k)[0])
            v = np.einsum("...ji,...j->...i", parent @ local, unit[..., child, :])
            side = HINGE_SIDE[k]
            # Twist about the rest direction (-z) by psi: v' = Rz(psi) v has v'_y = 0 and
            # v'_x on the hinge's side.
            psi = np.arctan2(-side * v[..., 1], side * v[..., 0])
            local = local @ rotvec_to_matrix(psi[..., None] * np.asarray(DOWN))
        angles[..., DOF_SLICES[k]] = matrix_to_rotvec(local)
        frames[..., k, :, :] = parent @ local
    return angles, lengths


def positions_from_angles(angles: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Forward kinematics: ``angles (..., 43)`` and ``lengths (..., 17)`` (broadcast) ->
    ``(..., 17, 3)`` keypoints, pelvis at the origin."""
    angles = np.asarray(angles, dtype=np.float64)
    lengths = np.broadcast_to(np.asarray(lengths, dtype=np.float64), angles.shape[:-1] + (17,))
    positions = np.zeros(angles.shape[:-1] + (17, 3))
    frames = np.zeros(angles.shape[:-1] + (17, 3, 3))
    frames[..., ROOT, :, :] = rotvec_to_matrix(angles[..., DOF_SLICES[ROOT]])
    for k in FK_ORDER[1:]:
        dof = angles[..., DOF_SLICES[k]]
        local = hinge_matrix(dof[..., 0]) if k in HINGES else rotvec_to_matrix(dof)
        frames[..., k, :, :] = frames[..., PARENTS[k], :, :] @ local
        direction = frames[..., k, :, :] @ REST_DIRECTIONS[k]
        positions[..., k, :] = positions[..., PARENTS[k], :] + lengths[..., k, None] * direction
    return positions
