"""Root residual force: the force on the free root that the floor cannot supply (body weights).

qvel and qacc by finite differences of qpos (``mj_differentiatePos``, so the root's rotation
is differenced on the quaternion manifold), then ``mj_inverse`` with contacts disabled gives
the generalised force the motion needs. Its root translational part ``f`` (world frame) must
come from the floor: where some geom is within the contact height of the floor the floor can
push with any force in the friction cone ``|f_xy| <= mu f_z``, so the residual is the
distance from ``f`` to that cone; with nothing near the floor it is ``|f|``. Divided by the
body weight ``m g``: a body standing still needs exactly its weight from the floor (0), a
body held in the air needs it from nowhere (1), a body in ballistic flight needs nothing (0).
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np
from scipy.signal import butter, sosfiltfilt

from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.thresholds import CheckConfig


def lowpass(x: np.ndarray, fps: float, cutoff_hz: float) -> np.ndarray:
    """Zero-lag 4th-order Butterworth low-pass of ``x (T, ...)`` over time (unchanged when the
    cutoff is at or above Nyquist or the clip is too short to filter)."""
    if cutoff_hz <= 0 or cutoff_hz >= 0.5 * fps or x.shape[0] < 16:
        return x
    sos = butter(2, cutoff_hz, fs=fps, output="sos")  # order 2 forward + backward = 4
    return sosfiltfilt(sos, x, axis=0)


def finite_qvel_qacc(
    model: mujoco.MjModel, qpos: np.ndarray, fps: float, cutoff_hz: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """``(T, nv)`` velocities (mean of the backward and forward differences) and
    accelerations (second differences) of ``qpos (T, nq)``; the ends repeat their neighbour.
    Differences are low-passed at ``cutoff_hz`` (0: not filtered)."""
    n, dt = qpos.shape[0], 1.0 / fps
    step = np.zeros((max(n - 1, 0), model.nv))  # step[t] = (q[t+1] - q[t]) / dt
    for t in range(n - 1):
        mujoco.mj_differentiatePos(model, step[t], dt, qpos[t], qpos[t + 1])
    step = lowpass(step, fps, cutoff_hz)
    if n < 3:
        return np.zeros((n, model.nv)), np.zeros((n, model.nv))
    qvel = np.empty((n, model.nv))
    qvel[1:-1] = 0.5 * (step[:-1] + step[1:])
    qvel[0], qvel[-1] = step[0], step[-1]
    qacc = np.empty((n, model.nv))
    qacc[1:-1] = np.diff(step, axis=0) / dt
    qacc[0], qacc[-1] = qacc[1], qacc[-2]
    return qvel, qacc


def cone_distance(force: np.ndarray, mu: float) -> np.ndarray:
    """``(T,)`` Euclidean distance of ``force (T, 3)`` to the cone ``|f_xy| <= mu f_z``."""
    s, z = np.linalg.norm(force[:, :2], axis=1), force[:, 2]
    inside = s <= mu * z
    polar = mu * s <= -z  # the projection is the apex
    to_surface = (s - mu * z) / np.sqrt(1.0 + mu * mu)
    return np.where(inside, 0.0, np.where(polar, np.hypot(s, z), to_surface))


def root_force(
    model: mujoco.MjModel, qpos: np.ndarray, fps: float, cutoff_hz: float = 0.0
) -> np.ndarray:
    """``(T, 3)`` world force on the free root that ``qpos (T, nq)`` needs, contacts off."""
    free = copy.deepcopy(model)
    free.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    data = mujoco.MjData(free)
    qvel, qacc = finite_qvel_qacc(free, qpos, fps, cutoff_hz)
    force = np.empty((qpos.shape[0], 3))
    for t in range(qpos.shape[0]):  # mj_inverse evaluates one state per call
        data.qpos[:], data.qvel[:], data.qacc[:] = qpos[t], qvel[t], qacc[t]
        mujoco.mj_inverse(free, data)
        force[t] = data.qfrc_inverse[:3]
    return force


class ResidualForceCheck:
    name = "residual_force"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        model = replay.model
        force = root_force(model, replay.qpos, replay.fps, config.residual_cutoff_hz)
        weight = model.body_mass.sum() * np.linalg.norm(model.opt.gravity)
        residual = (
            np.where(
                replay.supported,
                cone_distance(force, config.friction),
                np.linalg.norm(force, axis=1),
            )
            / weight
        )
        return CheckResult(
            name=self.name,
            per_frame={"residual_force_bw": residual},
            values={"residual_force_bw_p95": float(np.percentile(residual, 95))},
            flagged=residual > config.residual_force_bw_p95,
        )
