"""The differentiable forward-kinematics layer (ControllerPose §4.3, Fig. 6J): the network's
43 joint angles -> the 17 keypoints in 3D, in torch.

The same kinematics as :func:`avatar_models.body17_angles.positions_from_angles` (the
constants come from there; a test holds the two equal to 1e-6 m), written with torch ops so
that a position loss can flow back into the angles.
"""

from __future__ import annotations

import torch

from avatarsim.avatar_models.body17_angles import (
    DOF_SLICES,
    FK_ORDER,
    HINGES,
    PARENTS,
    REST_DIRECTIONS,
    ROOT,
)


def skew(v: torch.Tensor) -> torch.Tensor:
    """``(..., 3)`` -> ``(..., 3, 3)`` cross-product matrices."""
    zero = torch.zeros_like(v[..., 0])
    x, y, z = v.unbind(-1)
    return torch.stack(
        [
            torch.stack([zero, -z, y], -1),
            torch.stack([z, zero, -x], -1),
            torch.stack([-y, x, zero], -1),
        ],
        -2,
    )


def rotvec_to_matrix(rotvec: torch.Tensor) -> torch.Tensor:
    """``(..., 3)`` rotation vectors -> ``(..., 3, 3)`` (Rodrigues, Taylor series near 0 so
    that the gradient is finite at the rest pose)."""
    theta2 = (rotvec * rotvec).sum(-1)[..., None, None]
    small = theta2 < 1e-12
    safe2 = torch.where(small, torch.ones_like(theta2), theta2)
    theta = torch.sqrt(safe2)
    a = torch.where(small, 1.0 - theta2 / 6.0, torch.sin(theta) / theta)
    b = torch.where(small, 0.5 - theta2 / 24.0, (1.0 - torch.cos(theta)) / safe2)
    k = skew(rotvec)
    eye = torch.eye(3, dtype=rotvec.dtype, device=rotvec.device)
    return eye + a * k + b * (k @ k)


def hinge_matrix(angle: torch.Tensor) -> torch.Tensor:
    """``(...,)`` -> ``(..., 3, 3)`` rotations about y."""
    c, s = torch.cos(angle), torch.sin(angle)
    zero, one = torch.zeros_like(angle), torch.ones_like(angle)
    return torch.stack(
        [torch.stack([c, zero, s], -1), torch.stack([zero, one, zero], -1),
         torch.stack([-s, zero, c], -1)],
        -2,
    )  # fmt: skip


def forward_kinematics(angles: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
    """``angles (B, 43)``, ``lengths (B, 17)`` or ``(17,)`` -> keypoints ``(B, 17, 3)``,
    pelvis at the origin (:mod:`avatar_models.body17_angles`)."""
    lengths = lengths.to(angles.dtype).expand(angles.shape[:-1] + (17,))
    rest = torch.as_tensor(REST_DIRECTIONS, dtype=angles.dtype, device=angles.device)
    frames: dict[int, torch.Tensor] = {ROOT: rotvec_to_matrix(angles[..., DOF_SLICES[ROOT]])}
    points: dict[int, torch.Tensor] = {ROOT: torch.zeros_like(angles[..., :3])}
    for k in (int(i) for i in FK_ORDER[1:]):
        dof = angles[..., DOF_SLICES[k]]
        local = hinge_matrix(dof[..., 0]) if k in HINGES else rotvec_to_matrix(dof)
        parent = int(PARENTS[k])
        frames[k] = frames[parent] @ local
        points[k] = points[parent] + lengths[..., k, None] * (frames[k] @ rest[k])
    return torch.stack([points[k] for k in range(17)], -2)
