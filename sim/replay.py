"""Kinematic replay: put a qpos trajectory on a MuJoCo model frame by frame and record geometry.

Shapes: ``T`` frames, ``B`` MuJoCo bodies, ``G`` geoms, ``N`` contacts over all frames. Uses
MuJoCo's own kinematics and collision detection (``mj_kinematics`` + ``mj_collision``), so
penetration and self-contacts are what MuJoCo's contact solver would see, not a
re-implementation of it. The per-frame loop only calls MuJoCo and copies its arrays; every
derived quantity is computed afterwards over all frames at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from avatarsim.avatar_models.errors import MotionValueError


@dataclass(frozen=True)
class ReplayTrace:
    """What the humanoid did during a replay.

    Attributes:
        body_pos: ``(T, B, 3)`` world positions of every MuJoCo body (``xpos``).
        body_rot: ``(T, B, 3, 3)`` world rotation matrices of every body (``xmat``).
        lowest_point: ``(T,)`` lowest z of any body geom surface (metres; < 0 is in the floor).
        floor_penetration: ``(T,)`` deepest floor contact penetration from MuJoCo (metres, >= 0).
        floor_contacts: ``(T,)`` number of geom-floor contacts.
        geom_lowest: ``(T, G)`` lowest z of each geom's surface (NaN for the floor).
        contact_frame: ``(N,)`` frame of each MuJoCo contact.
        contact_geom: ``(N, 2)`` geom ids of each contact.
        contact_dist: ``(N,)`` signed distance (negative = penetration, metres).
        contact_pos: ``(N, 3)`` contact position in the world.
    """

    body_pos: np.ndarray
    body_rot: np.ndarray
    lowest_point: np.ndarray
    floor_penetration: np.ndarray
    floor_contacts: np.ndarray
    geom_lowest: np.ndarray
    contact_frame: np.ndarray
    contact_geom: np.ndarray
    contact_dist: np.ndarray
    contact_pos: np.ndarray

    def com(self, model: mujoco.MjModel) -> np.ndarray:
        """``(T, 3)`` whole-body centre of mass (mass-weighted body CoMs, ``xipos``)."""
        xipos = self.body_pos + np.einsum("tbij,bj->tbi", self.body_rot, model.body_ipos)
        return np.einsum("tbi,b->ti", xipos, model.body_mass) / model.body_mass.sum()


def floor_geoms(model: mujoco.MjModel) -> np.ndarray:
    """Ids of the plane geoms (the floor)."""
    return np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)


def geom_lowest_z(
    model: mujoco.MjModel, geom_xpos: np.ndarray, geom_xmat: np.ndarray
) -> np.ndarray:
    """``(T, G)`` lowest z of each geom from ``geom_xpos (T, G, 3)``, ``geom_xmat (T, G, 9)``:
    the analytic support in -Z of capsules, spheres, boxes and cylinders (NaN for planes)."""
    size = model.geom_size
    axis_z = np.abs(geom_xmat.reshape(*geom_xmat.shape[:2], 3, 3)[:, :, 2, :])  # |z of axes|
    gtype = model.geom_type
    extent = np.broadcast_to(size[:, 0], axis_z.shape[:2]).copy()  # sphere radius
    box = gtype == mujoco.mjtGeom.mjGEOM_BOX
    capsule = gtype == mujoco.mjtGeom.mjGEOM_CAPSULE
    cylinder = gtype == mujoco.mjtGeom.mjGEOM_CYLINDER
    extent[:, box] = np.sum(axis_z[:, box] * size[box], axis=-1)
    extent[:, capsule] = size[capsule, 0] + axis_z[:, capsule, 2] * size[capsule, 1]
    radial = np.sqrt(np.clip(1.0 - axis_z[:, cylinder, 2] ** 2, 0.0, 1.0))
    extent[:, cylinder] = size[cylinder, 0] * radial + axis_z[:, cylinder, 2] * size[cylinder, 1]
    lowest = geom_xpos[:, :, 2] - extent
    lowest[:, gtype == mujoco.mjtGeom.mjGEOM_PLANE] = np.nan
    return lowest


def replay_kinematic(model: mujoco.MjModel, qpos: np.ndarray) -> ReplayTrace:
    """Replay ``qpos (T, nq)`` kinematically (no dynamics) and record geometry per frame."""
    qpos = np.asarray(qpos, dtype=float)
    if qpos.ndim != 2 or qpos.shape[1] != model.nq:
        raise MotionValueError(f"qpos must be (T, {model.nq}), got {qpos.shape}")
    if not np.all(np.isfinite(qpos)):
        raise MotionValueError("qpos contains NaN or inf")
    data = mujoco.MjData(model)
    n = qpos.shape[0]
    body_pos = np.empty((n, model.nbody, 3))
    body_rot = np.empty((n, model.nbody, 9))
    geom_xpos = np.empty((n, model.ngeom, 3))
    geom_xmat = np.empty((n, model.ngeom, 9))
    # Views of MjData's buffers fetched once: each attribute access builds a new array object,
    # which costs as much as the copy itself at this size.
    q_in, xpos, xmat, gpos, gmat = data.qpos, data.xpos, data.xmat, data.geom_xpos, data.geom_xmat
    counts = np.zeros(n, dtype=np.int64)
    geoms, dists, positions = [], [], []
    for t in range(n):  # MuJoCo evaluates one configuration per call
        q_in[:] = qpos[t]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        body_pos[t] = xpos
        body_rot[t] = xmat
        geom_xpos[t] = gpos
        geom_xmat[t] = gmat
        if data.ncon:
            con = data.contact
            counts[t] = data.ncon
            geoms.append(con.geom.copy())
            dists.append(con.dist.copy())
            positions.append(con.pos.copy())
    cat = np.concatenate
    contact_frame = np.repeat(np.arange(n), counts)
    contact_geom = cat(geoms) if geoms else np.zeros((0, 2), dtype=np.int64)
    contact_dist = cat(dists) if dists else np.zeros(0)
    contact_pos = cat(positions) if positions else np.zeros((0, 3))
    geom_lowest = geom_lowest_z(model, geom_xpos, geom_xmat)
    solid = model.geom_bodyid > 0
    on_floor = np.isin(contact_geom, floor_geoms(model)).any(axis=1)
    penetration = np.zeros(n)
    np.maximum.at(penetration, contact_frame[on_floor], -contact_dist[on_floor])
    return ReplayTrace(
        body_pos=body_pos,
        body_rot=body_rot.reshape(n, model.nbody, 3, 3),
        lowest_point=np.min(geom_lowest[:, solid], axis=1),
        floor_penetration=penetration,
        floor_contacts=np.bincount(contact_frame[on_floor], minlength=n),
        geom_lowest=geom_lowest,
        contact_frame=contact_frame,
        contact_geom=contact_geom,
        contact_dist=contact_dist,
        contact_pos=contact_pos,
    )
