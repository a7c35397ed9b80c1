"""The humanoid as the controller simulates it: the control variant of the model
(:func:`control_model`) and the ids the controller addresses in it (:class:`BodyIndices`).

Shapes: ``nu`` actuated hinges, ``G`` sole boxes, 8 corners each.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from avatarsim.avatar_models.body import control_spec
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.sim.soles import ANKLE_SITES, box_corners, foot_bodies, sole_boxes, thigh_bodies


def control_model(spec: mujoco.MjSpec) -> mujoco.MjModel:
    """The humanoid as the controller simulates it, compiled from its ``spec`` (e.g.
    :attr:`sim.humanoid.Humanoid.spec`) through :func:`avatar_models.body.control_spec`: the
    actuators are motors (``ctrl`` is the torque) and only the floor collides with the body.
    ``spec`` is not changed.

    Raises :class:`MotionValueError` unless every actuator drives a hinge (none the root).
    """
    model = control_spec(spec).compile()
    if model.nu == 0 or np.any(model.jnt_type[model.actuator_trnid[:, 0]] == 0):
        raise MotionValueError("control needs hinge actuators and no actuator on the root")
    return model


def is_control_model(model: mujoco.MjModel) -> bool:
    """Whether ``model``'s actuators are motors (unit gain, no bias, no clamp), as
    :func:`control_model` makes them."""
    gain = np.zeros_like(model.actuator_gainprm)
    gain[:, 0] = 1.0
    return bool(
        np.array_equal(model.actuator_gainprm, gain)
        and not model.actuator_biasprm.any()
        and not model.actuator_ctrllimited.any()
    )


@dataclass(frozen=True)
class BodyIndices:
    """What the controller addresses in the humanoid model (found through the body17 sites,
    never a rig's bone names, as :mod:`sim.soles`).

    Attributes:
        dof, hinge_qadr: ``(nu,)`` velocity and position addresses of the actuated hinges.
        sites: ``(17,)`` body17 site ids.
        ankles: ``(2,)`` left and right ankle site ids.
        feet: left and right foot body ids.
        hip_dof, hip_qadr: per leg, ``(H,)`` velocity and position addresses of the hip
            hinges (the thigh body's joints).
        sole_geoms: ``(G,)`` box geoms of the feet and toes; ``sole_corners (G, 8, 3)`` their
            corners in the geom frame (the lowest ones are the sole's).
        sole_normal: per foot, ``(3,)`` the sole's normal in the foot frame (the world's +Z
            in the rest pose, which stands flat-footed on the floor).
    """

    dof: np.ndarray
    hinge_qadr: np.ndarray
    sites: np.ndarray
    ankles: np.ndarray
    feet: list[int]
    hip_dof: list[np.ndarray]
    hip_qadr: list[np.ndarray]
    sole_geoms: np.ndarray
    sole_corners: np.ndarray
    sole_normal: list[np.ndarray]

    @classmethod
    def of(cls, model: mujoco.MjModel) -> BodyIndices:
        """The indices of ``model``; :class:`MotionValueError` without box feet."""
        sole_geoms = sole_boxes(model)
        if sole_geoms.size == 0:
            raise MotionValueError("control needs box feet (the sole corners are contacts)")
        feet = [model.body(name).id for name in foot_bodies(model)]
        hips = [
            np.flatnonzero(model.jnt_bodyid == model.body(name).id) for name in thigh_bodies(model)
        ]
        rest = mujoco.MjData(model)
        mujoco.mj_kinematics(model, rest)  # qpos0 stands flat-footed on the floor
        return cls(
            dof=model.jnt_dofadr[model.actuator_trnid[:, 0]],
            hinge_qadr=model.jnt_qposadr[model.actuator_trnid[:, 0]],
            sites=site_ids(model, BODY17),
            ankles=site_ids(model, ANKLE_SITES),
            feet=feet,
            hip_dof=[model.jnt_dofadr[j] for j in hips],
            hip_qadr=[model.jnt_qposadr[j] for j in hips],
            sole_geoms=sole_geoms,
            sole_corners=box_corners(model, sole_geoms),
            sole_normal=[rest.xmat[b].reshape(3, 3)[2] for b in feet],  # R^T z
        )


def site_ids(model: mujoco.MjModel, names: tuple[str, ...]) -> np.ndarray:
    """``(len(names),)`` ids of the sites ``names``."""
    return np.array([mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, n) for n in names])
