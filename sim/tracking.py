"""Physics tracking: the humanoid follows a reference ``qpos`` under simulation, root unactuated.

Shapes: ``T`` reference frames, ``nq``/``nv``/``nu`` MuJoCo sizes, 17 body17 sites.

Control, once per reference frame (held for the simulation steps in between):

* PD on every hinge through the body's own position actuators (``kp``, ``kv`` from
  :mod:`avatar_models.body.mjcf`): ``tau = kp (q_ref - q) + kv (qd_ref - qd)``;
* inverse-dynamics feedforward: ``mj_inverse`` on the reference (``q``, ``qd``, ``qdd`` by
  finite differences), keeping the hinge torques and dropping the root's 6 entries, which
  no motor could produce;

* balance (Yin et al. 2007, SIMBICON: stance-hip torque controls the torso): a PD torque
  ``T = k_r e(R_ref R^T) + d_r (w_ref - w)`` on the root's world orientation, produced by
  the hips of the legs the reference stands on, ``tau_hinge = -axis . T`` (the Jacobian
  transpose, so the pelvis feels ``T`` as the reaction of internal joint torques);

all enter as the actuator's set-point, ``ctrl = q_ref + (tau_ff + tau_bal + kv qd_ref) / kp``,
so all joint torque is actuator force and is reported as such. The set-point may leave the joint
range (a feedforward torque near a limit), so the tracking model copy lifts the actuators'
``ctrlrange`` clamp; joint ranges themselves stay. Nothing acts on the root: no actuator on
the free joint, ``xfrc_applied`` and ``qfrc_applied`` stay zero.

A fall (after Peng et al. 2018, DeepMimic, whose episodes end when the character falls) is
the first frame where the head is below :attr:`TrackingSettings.fall_head_ratio` of the
reference head height, or the root's up axis is tilted more than
:attr:`TrackingSettings.fall_tilt_deg` away from the reference root's.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from avatar_models.body17 import BODY17
from avatar_models.errors import MotionValueError

ROOT_DOF = 6


@dataclass(frozen=True)
class TrackingSettings:
    """Controller and fall criteria.

    Attributes:
        feedforward: add the inverse-dynamics hinge torques of the reference.
        gain_scale: factor on the actuators' ``kp`` and ``kv``.
        fall_head_ratio: fall when head height < this x the reference head height.
        fall_tilt_deg: fall when the root's up axis is this far from the reference's.
        balance_gain: root orientation stiffness ``k_r`` as a multiple of ``m g H`` (N m/rad
            for body mass ``m``, stature ``H``); 0 turns balance off.
        balance_damping_s: ``d_r / k_r``.
        stance_height: a foot stands in the reference while its ankle site is within this of
            the ankle's lowest height in the clip (metres). ``H`` is the rest head height.
    """

    feedforward: bool = True
    gain_scale: float = 1.0
    balance_gain: float = 1.0
    balance_damping_s: float = 0.1
    stance_height: float = 0.03
    fall_head_ratio: float = 0.6
    fall_tilt_deg: float = 60.0


@dataclass(frozen=True)
class TrackingResult:
    """What the simulated humanoid did.

    Attributes:
        qpos: ``(T, nq)`` simulated configuration at each reference frame.
        body17_error: ``(T, 17)`` distance (metres) of each body17 site from the reference.
        torque: ``(T, nu)`` actuator torques (N m) at each frame.
        power: ``(T,)`` mechanical power sum |tau * qd| over the hinges (W).
        fall_frame: first frame judged fallen, or ``None``.
        fps: reference frame rate.
    """

    qpos: np.ndarray
    body17_error: np.ndarray
    torque: np.ndarray
    power: np.ndarray
    fall_frame: int | None
    fps: float

    @property
    def fell(self) -> bool:
        return self.fall_frame is not None

    @property
    def fall_time_s(self) -> float | None:
        return None if self.fall_frame is None else self.fall_frame / self.fps

    @property
    def upright_frames(self) -> slice:
        """The frames before the fall (all frames if it never fell)."""
        return slice(0, self.fall_frame)

    def summary(self) -> dict:
        """Report numbers: body17 error per joint (cm, mean over upright frames), mean and
        p95 overall, fall time, energy (J), mean absolute torque (N m)."""
        err = 100.0 * self.body17_error[self.upright_frames]
        duration = self.qpos.shape[0] / self.fps
        return {
            "body17_err_cm": dict(zip(BODY17, np.round(err.mean(0), 2).tolist(), strict=True)),
            "body17_err_cm_mean": float(err.mean()),
            "body17_err_cm_p95": float(np.percentile(err, 95)),
            "fell": self.fell,
            "fall_time_s": self.fall_time_s,
            "duration_s": duration,
            "energy_j": float(self.power.sum() / self.fps),
            "mean_abs_torque_nm": float(np.abs(self.torque).mean()),
        }


def reference_velocities(model: mujoco.MjModel, qpos: np.ndarray, fps: float) -> np.ndarray:
    """``(T, nv)`` velocities of ``qpos (T, nq)`` by central differences on the manifold
    (``mj_differentiatePos``, so the root quaternion is handled)."""
    n = qpos.shape[0]
    dt = 1.0 / fps
    forward = np.zeros((n, model.nv))
    for t in range(n - 1):  # one MuJoCo call per frame pair
        mujoco.mj_differentiatePos(model, forward[t], dt, qpos[t], qpos[t + 1])
    if n > 1:
        forward[-1] = forward[-2]
    backward = np.vstack([forward[:1], forward[:-1]])
    return 0.5 * (forward + backward)


class Tracker:
    """A simulation of ``model`` (the humanoid MJCF) tracking references. See the module
    docstring for the controller. ``data`` is exposed so callers can inspect the state."""

    def __init__(self, model: mujoco.MjModel, settings: TrackingSettings | None = None):
        if model.nu == 0 or np.any(model.jnt_type[model.actuator_trnid[:, 0]] == 0):
            raise MotionValueError("tracking needs hinge actuators and no actuator on the root")
        self.settings = settings or TrackingSettings()
        self.model = model
        self.model.actuator_ctrllimited[:] = 0  # set-points carry feedforward (module doc)
        scale = self.settings.gain_scale
        self.kp = model.actuator_gainprm[:, 0] * scale
        self.kv = -model.actuator_biasprm[:, 2] * scale
        model.actuator_gainprm[:, 0] = self.kp
        model.actuator_biasprm[:, 1] = -self.kp
        model.actuator_biasprm[:, 2] = -self.kv
        self.data = mujoco.MjData(model)
        self.dof = model.jnt_dofadr[model.actuator_trnid[:, 0]]
        self.qadr = model.jnt_qposadr[model.actuator_trnid[:, 0]]
        self.sites = np.array(
            [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, n) for n in BODY17]
        )
        self.hips = [self._body_actuators(side) for side in ("l_hip", "r_hip")]
        weight = float(model.body_subtreemass[1]) * float(-model.opt.gravity[2])
        mujoco.mj_kinematics(model, self.data)  # qpos0: standing on the floor in rest pose
        height = float(self.data.site_xpos[self.sites[BODY17.index("head")], 2])
        self.balance_kp = self.settings.balance_gain * weight * height
        self.balance_kd = self.balance_kp * self.settings.balance_damping_s

    def _body_actuators(self, site: str) -> np.ndarray:
        """Actuators of the hinges of the body that carries body17 ``site``."""
        body = self.model.site_bodyid[self.sites[BODY17.index(site)]]
        return np.flatnonzero(self.model.jnt_bodyid[self.model.actuator_trnid[:, 0]] == body)

    def stance(self, ref_sites: np.ndarray) -> np.ndarray:
        """``(T, 2)`` weight of the left and right leg in the reference's support (0..1)."""
        ankles = ref_sites[:, [BODY17.index("l_ankle"), BODY17.index("r_ankle")], 2]
        down = ankles < ankles.min(axis=0) + self.settings.stance_height
        total = down.sum(axis=1, keepdims=True)
        return np.divide(down, total, out=np.zeros(down.shape), where=total > 0)

    def balance_torque(self, quat_ref: np.ndarray, omega_ref: np.ndarray, stance) -> np.ndarray:
        """``(nu,)`` stance-hip hinge torques that turn the root towards ``quat_ref`` (wxyz),
        at world angular velocity ``omega_ref``; see the module docstring."""
        d = self.data
        err_quat = np.empty(4)
        conj = np.empty(4)
        mujoco.mju_negQuat(conj, d.qpos[3:7])
        mujoco.mju_mulQuat(err_quat, quat_ref, conj)
        err = np.empty(3)
        mujoco.mju_quat2Vel(err, err_quat, 1.0)
        omega = d.xmat[1].reshape(3, 3) @ d.qvel[3:6]
        torque = self.balance_kp * err + self.balance_kd * (omega_ref - omega)
        out = np.zeros(self.model.nu)
        axes = d.xaxis[self.model.actuator_trnid[:, 0]]
        for weight, hip in zip(stance, self.hips, strict=True):
            out[hip] = -weight * (axes[hip] @ torque)
        return out

    def feedforward(self, qpos: np.ndarray, qvel: np.ndarray, fps: float) -> np.ndarray:
        """``(T, nu)`` hinge torques from ``mj_inverse`` on the reference (root dropped)."""
        qacc = np.gradient(qvel, 1.0 / fps, axis=0) if qpos.shape[0] > 1 else 0 * qvel
        data = mujoco.MjData(self.model)
        out = np.empty((qpos.shape[0], self.model.nu))
        for t in range(qpos.shape[0]):  # MuJoCo evaluates one state per call
            data.qpos[:], data.qvel[:], data.qacc[:] = qpos[t], qvel[t], qacc[t]
            mujoco.mj_inverse(self.model, data)
            out[t] = data.qfrc_inverse[self.dof]
        return out

    def reference_sites(self, qpos: np.ndarray) -> np.ndarray:
        """``(T, 17, 3)`` body17 site positions of ``qpos (T, nq)`` (kinematics only)."""
        data = mujoco.MjData(self.model)
        out = np.empty((qpos.shape[0], len(BODY17), 3))
        for t in range(qpos.shape[0]):
            data.qpos[:] = qpos[t]
            mujoco.mj_kinematics(self.model, data)
            out[t] = data.site_xpos[self.sites]
        return out

    def run(self, qpos_ref: np.ndarray, fps: float) -> TrackingResult:
        """Track ``qpos_ref (T, nq)`` sampled at ``fps`` from its first frame, at rest-free
        initial velocity equal to the reference's."""
        qpos_ref = np.asarray(qpos_ref, dtype=float)
        m, d = self.model, self.data
        if qpos_ref.ndim != 2 or qpos_ref.shape[1] != m.nq or not np.isfinite(qpos_ref).all():
            raise MotionValueError(f"reference must be finite (T, {m.nq}), got {qpos_ref.shape}")
        n = qpos_ref.shape[0]
        qvel_ref = reference_velocities(m, qpos_ref, fps)
        hinge_v = qvel_ref[:, self.dof]
        tau_ff = self.feedforward(qpos_ref, qvel_ref, fps) if self.settings.feedforward else 0.0
        ctrl = qpos_ref[:, self.qadr] + (tau_ff + self.kv * hinge_v) / self.kp
        substeps = max(1, round(1.0 / (fps * m.opt.timestep)))
        ref_sites = self.reference_sites(qpos_ref)
        stance = self.stance(ref_sites)
        omega_ref = self._world_angular_velocity(qpos_ref, qvel_ref)
        balance = self.settings.balance_gain > 0

        mujoco.mj_resetData(m, d)
        d.qpos[:], d.qvel[:] = qpos_ref[0], qvel_ref[0]
        qpos = np.empty((n, m.nq))
        sites = np.empty((n, len(BODY17), 3))
        torque = np.empty((n, m.nu))
        power = np.empty(n)
        for t in range(n):  # the simulation is sequential by nature
            for _ in range(substeps):
                d.ctrl[:] = ctrl[t]
                if balance:
                    tau = self.balance_torque(qpos_ref[t, 3:7], omega_ref[t], stance[t])
                    d.ctrl[:] += tau / self.kp
                mujoco.mj_step(m, d)
            qpos[t] = d.qpos
            sites[t] = d.site_xpos[self.sites]
            torque[t] = d.actuator_force
            power[t] = np.abs(d.actuator_force * d.qvel[self.dof]).sum()
        return TrackingResult(
            qpos=qpos,
            body17_error=np.linalg.norm(sites - ref_sites, axis=-1),
            torque=torque,
            power=power,
            fall_frame=self._fall_frame(qpos, qpos_ref, sites, ref_sites),
            fps=fps,
        )

    def _world_angular_velocity(self, qpos: np.ndarray, qvel: np.ndarray) -> np.ndarray:
        """``(T, 3)`` world angular velocity of the root (MuJoCo's free-joint angular
        velocity is in the root's local frame)."""
        mats = np.empty((qpos.shape[0], 9))
        for t in range(qpos.shape[0]):
            mujoco.mju_quat2Mat(mats[t], qpos[t, 3:7])
        return np.einsum("tab,tb->ta", mats.reshape(-1, 3, 3), qvel[:, 3:6])

    def _fall_frame(self, qpos, qpos_ref, sites, ref_sites) -> int | None:
        head = BODY17.index("head")
        low = sites[:, head, 2] < self.settings.fall_head_ratio * ref_sites[:, head, 2]
        tilt = np.degrees(np.arccos(np.clip(np.sum(_up(qpos) * _up(qpos_ref), -1), -1, 1)))
        fallen = np.flatnonzero(low | (tilt > self.settings.fall_tilt_deg))
        return int(fallen[0]) if fallen.size else None


def _up(qpos: np.ndarray) -> np.ndarray:
    """``(T, 3)`` world direction of the root's local +Z from the wxyz quaternion."""
    w, x, y, z = qpos[:, 3:7].T
    return np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], axis=1)


def track(
    model: mujoco.MjModel,
    qpos_ref: np.ndarray,
    fps: float,
    settings: TrackingSettings | None = None,
) -> TrackingResult:
    """Track ``qpos_ref (T, nq)`` at ``fps`` with a fresh :class:`Tracker` on ``model``
    (which it modifies: build one model per tracker)."""
    return Tracker(model, settings).run(qpos_ref, fps)
