"""The soles of the humanoid's feet: its box geoms below each foot body, and their corners.

Bodies are found through the body17 sites the MJCF places on them (the ankle site sits on the
foot body, the hip site on the thigh), never by a rig's bone names, so every rig's humanoid
(avatar, CMU, a built-in subject) works alike.

Shapes: ``G`` sole boxes, 8 corners each.
"""

from __future__ import annotations

import mujoco
import numpy as np

ANKLE_SITES = ("l_ankle", "r_ankle")
HIP_SITES = ("l_hip", "r_hip")
BALL_SITES = ("l_foot", "r_foot")
_SIGNS = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1], indexing="ij")).reshape(3, -1).T


def site_bodies(model: mujoco.MjModel, sites: tuple[str, ...]) -> tuple[str, ...]:
    """Names of the bodies that carry the body17 ``sites``, in their order."""
    return tuple(model.body(model.site_bodyid[model.site(name).id]).name for name in sites)


def foot_bodies(model: mujoco.MjModel) -> tuple[str, str]:
    """The left and right foot bodies (those of the ankle sites)."""
    return site_bodies(model, ANKLE_SITES)


def toe_bodies(model: mujoco.MjModel) -> tuple[str, ...]:
    """The toe bodies (those of the ball-of-foot sites), where a rig has them below the foot."""
    feet = foot_bodies(model)
    return tuple(b for b in site_bodies(model, BALL_SITES) if b not in feet)


def thigh_bodies(model: mujoco.MjModel) -> tuple[str, str]:
    """The left and right thigh bodies (those of the hip sites)."""
    return site_bodies(model, HIP_SITES)


def subtree_mask(model: mujoco.MjModel, names: tuple[str, ...]) -> np.ndarray:
    """``(nbody,)`` bool: the bodies ``names`` and every body below them."""
    mask = np.isin(np.arange(model.nbody), [model.body(name).id for name in names])
    for b in range(1, model.nbody):  # parents come before children in MuJoCo's order
        mask[b] |= mask[model.body_parentid[b]]
    return mask


def sole_boxes(model: mujoco.MjModel, feet: tuple[str, ...] | None = None) -> np.ndarray:
    """``(G,)`` ids of the box geoms on the bodies ``feet`` (default: both
    :func:`foot_bodies`) and below them (the toes)."""
    below = subtree_mask(model, foot_bodies(model) if feet is None else feet)
    return np.flatnonzero(below[model.geom_bodyid] & (model.geom_type == mujoco.mjtGeom.mjGEOM_BOX))


def box_corners(model: mujoco.MjModel, geoms: np.ndarray) -> np.ndarray:
    """``(G, 8, 3)`` corners of the box ``geoms`` in their own frames."""
    return _SIGNS[None] * model.geom_size[geoms][:, None]


def corner_positions(data: mujoco.MjData, geoms: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """``(G, 8, 3)`` world positions of ``corners (G, 8, 3)`` (:func:`box_corners`) of
    ``geoms (G,)`` in the current kinematics of ``data``."""
    axes = data.geom_xmat[geoms].reshape(-1, 3, 3)
    return data.geom_xpos[geoms][:, None] + np.einsum("gij,gkj->gki", axes, corners)
