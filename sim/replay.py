"""Kinematic replay: put a qpos trajectory on a MuJoCo model frame by frame and record geometry.

Shapes: ``T`` frames, ``B`` MuJoCo bodies. Uses MuJoCo's own kinematics and collision
detection (``mj_kinematics`` + ``mj_collision``), so penetration is what MuJoCo's contact
solver would see, not a re-implementation of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from avatar_models.errors import MotionValueError


@dataclass(frozen=True)
class ReplayTrace:
    """What the humanoid did during a replay.

    Attributes:
        body_pos: ``(T, B, 3)`` world positions of every MuJoCo body (``xpos``).
        lowest_point: ``(T,)`` lowest z of any body geom surface (metres; < 0 is in the floor).
        floor_penetration: ``(T,)`` deepest floor contact penetration from MuJoCo (metres, >= 0).
        floor_contacts: ``(T,)`` number of geom-floor contacts.
    """

    body_pos: np.ndarray
    lowest_point: np.ndarray
    floor_penetration: np.ndarray
    floor_contacts: np.ndarray


def _floor_geoms(model: mujoco.MjModel) -> np.ndarray:
    return np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)


def _lowest_surface_z(model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray) -> float:
    """Lowest z over capsule, sphere, box and cylinder geoms (analytic support in -Z)."""
    size = model.geom_size[geoms]
    xmat = data.geom_xmat[geoms].reshape(-1, 3, 3)
    center_z = data.geom_xpos[geoms, 2]
    axis_z = np.abs(xmat[:, 2, :])  # |z component| of each local axis in world
    gtype = model.geom_type[geoms]
    box = gtype == mujoco.mjtGeom.mjGEOM_BOX
    capsule = gtype == mujoco.mjtGeom.mjGEOM_CAPSULE
    cylinder = gtype == mujoco.mjtGeom.mjGEOM_CYLINDER
    extent = size[:, 0].copy()  # sphere radius
    extent[box] = np.sum(axis_z[box] * size[box], axis=1)
    extent[capsule] = size[capsule, 0] + axis_z[capsule, 2] * size[capsule, 1]
    radial = np.sqrt(np.clip(1.0 - axis_z[cylinder, 2] ** 2, 0.0, 1.0))
    extent[cylinder] = size[cylinder, 0] * radial + axis_z[cylinder, 2] * size[cylinder, 1]
    return float(np.min(center_z - extent))


def replay_kinematic(model: mujoco.MjModel, qpos: np.ndarray) -> ReplayTrace:
    """Replay ``qpos (T, nq)`` kinematically (no dynamics) and record geometry per frame."""
    qpos = np.asarray(qpos, dtype=float)
    if qpos.ndim != 2 or qpos.shape[1] != model.nq:
        raise MotionValueError(f"qpos must be (T, {model.nq}), got {qpos.shape}")
    if not np.all(np.isfinite(qpos)):
        raise MotionValueError("qpos contains NaN or inf")
    data = mujoco.MjData(model)
    floors = _floor_geoms(model)
    solid = np.setdiff1d(np.flatnonzero(model.geom_bodyid > 0), floors)
    n = qpos.shape[0]
    body_pos = np.empty((n, model.nbody, 3))
    lowest = np.empty(n)
    pen = np.zeros(n)
    contacts = np.zeros(n, dtype=np.int64)
    for t in range(n):  # MuJoCo evaluates one configuration per call
        data.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        body_pos[t] = data.xpos
        lowest[t] = _lowest_surface_z(model, data, solid)
        con = data.contact[: data.ncon]
        on_floor = np.isin(con.geom1, floors) | np.isin(con.geom2, floors)
        contacts[t] = int(on_floor.sum())
        if contacts[t]:
            pen[t] = max(0.0, float(-con.dist[on_floor].min()))
    return ReplayTrace(body_pos, lowest, pen, contacts)
