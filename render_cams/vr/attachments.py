"""Rigid attachments: a device held at a fixed offset from a skeleton joint.

An :class:`Attachment` names a ``body17`` joint and an offset pose in that joint's frame. The
device's world pose is the joint's global pose composed with the offset::

    R_device = R_joint @ R_offset,      p_device = p_joint + R_joint @ p_offset

Joint frames: every avatarsim rig has identity local rotations in its rest pose, so at rest a
joint's frame is the body frame (+X forward, +Y left, +Z up) whatever the rig; offsets are
therefore rig-independent where they are written in that frame. Users wear devices a little
differently; :class:`OffsetSpread` draws such per-user offsets for simulated users (AvatarGo,
shared/papers/avatargo.txt §3.3, calibrates the trackers' offsets to the avatar's joints at a
T-pose instead, :mod:`synthesis.avatargo`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import Motion, MotionValueError, quat
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams.device import DeviceError


@dataclass(frozen=True, eq=False)  # array fields: compare with as_dict(), not ==
class Attachment:
    """A device rigidly fixed to a joint.

    Attributes:
        joint: the ``body17`` name of the joint (``"head"``, ``"l_wrist"``...).
        position: ``(3,)`` offset of the device origin in the joint frame (metres).
        rotation: ``(4,)`` wxyz orientation of the device in the joint frame.
    """

    joint: str
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray = field(default_factory=lambda: quat.IDENTITY.copy())

    def __post_init__(self) -> None:
        if self.joint not in BODY17:
            raise DeviceError(
                f"attachment joint {self.joint!r} is not a body17 joint; use one of "
                f"{', '.join(BODY17)}"
            )
        pos = np.asarray(self.position, dtype=float).reshape(-1)
        rot = np.asarray(self.rotation, dtype=float).reshape(-1)
        if pos.shape != (3,) or not np.all(np.isfinite(pos)):
            raise DeviceError(f"attachment position must be 3 finite metres, got {self.position}")
        if rot.shape != (4,) or not np.all(np.isfinite(rot)) or np.linalg.norm(rot) < 1e-9:
            raise DeviceError(f"attachment rotation must be a wxyz quaternion, got {rot}")
        object.__setattr__(self, "position", pos)
        object.__setattr__(self, "rotation", quat.normalize(rot))

    def as_dict(self) -> dict:
        """JSON-ready description (for stream metadata)."""
        return {
            "joint": self.joint,
            "position": self.position.tolist(),
            "rotation": self.rotation.tolist(),
        }


@dataclass(frozen=True)
class OffsetSpread:
    """How far one user's device offsets stray from the nominal ones (Gaussian, per axis).

    Defaults are assumptions, not measurements: 1 cm in position (a strap or grip placed a
    finger-width differently) and 5 degrees in rotation.
    """

    position_sigma_m: float = 0.01
    rotation_sigma_rad: float = float(np.radians(5.0))

    def __post_init__(self) -> None:
        for name in ("position_sigma_m", "rotation_sigma_rad"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise DeviceError(f"OffsetSpread.{name} must be >= 0, got {value!r}")

    def perturb(self, attachment: Attachment, rng: np.random.Generator) -> Attachment:
        """``attachment`` moved by a random offset (position in the joint frame) and turned by a
        random rotation (in the device's own frame)."""
        dp = rng.normal(0.0, self.position_sigma_m, 3)
        dr = quat.from_scipy(Rotation.from_rotvec(rng.normal(0.0, self.rotation_sigma_rad, 3)))
        return Attachment(
            attachment.joint,
            attachment.position + dp,
            quat.mul(attachment.rotation, dr[0]),
        )


def attachment_poses(
    motion: Motion, attachments: Sequence[Attachment]
) -> tuple[np.ndarray, np.ndarray]:
    """World poses of devices attached to ``motion``'s skeleton, vectorised over frames.

    Returns:
        positions ``(T, D, 3)`` and quaternions ``(T, D, 4)`` (wxyz, continuous in time).
    Raises:
        RigError if the skeleton matches no rig; MotionValueError if its pose is not finite.
    """
    rig = identify_rig(motion.skeleton)
    joints = motion.skeleton.indices([rig.body17[a.joint] for a in attachments])
    pos, rot = motion.fk()
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(rot))):
        raise MotionValueError("motion pose has NaN/inf; cannot place devices on it")
    offset_pos = np.stack([a.position for a in attachments])  # (D, 3)
    offset_rot = quat.to_matrix(np.stack([a.rotation for a in attachments]))  # (D, 3, 3)
    joint_rot = rot[:, joints]  # (T, D, 3, 3)
    positions = pos[:, joints] + np.einsum("tdab,db->tda", joint_rot, offset_pos)
    quaternions = quat.make_continuous(quat.from_matrix(joint_rot @ offset_rot))
    return positions, quaternions
