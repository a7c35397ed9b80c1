"""The soles of the humanoid's feet: its box geoms below each foot body, and their corners.

Shapes: ``G`` sole boxes, 8 corners each.
"""

from __future__ import annotations

import mujoco
import numpy as np

FEET = ("Bip01 L Foot", "Bip01 R Foot")
_SIGNS = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1], indexing="ij")).reshape(3, -1).T


def subtree_mask(model: mujoco.MjModel, names: tuple[str, ...]) -> np.ndarray:
    """``(nbody,)`` bool: the bodies ``names`` and every body below them."""
    mask = np.isin(np.arange(model.nbody), [model.body(name).id for name in names])
    for b in range(1, model.nbody):  # parents come before children in MuJoCo's order
        mask[b] |= mask[model.body_parentid[b]]
    return mask


def sole_boxes(model: mujoco.MjModel, feet: tuple[str, ...] = FEET) -> np.ndarray:
    """``(G,)`` ids of the box geoms on the bodies ``feet`` and below them (the toes)."""
    below = subtree_mask(model, feet)
    return np.flatnonzero(below[model.geom_bodyid] & (model.geom_type == mujoco.mjtGeom.mjGEOM_BOX))


def box_corners(model: mujoco.MjModel, geoms: np.ndarray) -> np.ndarray:
    """``(G, 8, 3)`` corners of the box ``geoms`` in their own frames."""
    return _SIGNS[None] * model.geom_size[geoms][:, None]


def corner_positions(data: mujoco.MjData, geoms: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """``(G, 8, 3)`` world positions of ``corners (G, 8, 3)`` (:func:`box_corners`) of
    ``geoms (G,)`` in the current kinematics of ``data``."""
    axes = data.geom_xmat[geoms].reshape(-1, 3, 3)
    return data.geom_xpos[geoms][:, None] + np.einsum("gij,gkj->gki", axes, corners)
