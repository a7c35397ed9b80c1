"""Physics tracking: the humanoid follows a reference ``qpos`` under simulation, root unactuated.

Shapes: ``T`` reference frames, ``nq``/``nv``/``nu`` MuJoCo sizes, ``C`` floor contacts, 17
body17 sites.

Controller: whole-body inverse dynamics with contact-force optimisation (the standard
task-space / QP controller of legged robots and physics-based characters, e.g. de Lasa et al.
2010 "Feature-based locomotion controllers"; Wensing & Orin 2013). At every control step:

* desired accelerations of ALL ``nv`` dofs, root included:
  ``qacc_des = qacc_ref + Kp (q_ref ⊖ q) + Kd (qvel_ref - qvel)`` (``mj_differentiatePos``
  for the free joint), and for each foot a world-orientation task
  ``J_rot qacc ≈ Kp_f log(R_ref Rᵀ) + Kd_f (w_ref - w)`` so a foot lands flat;
* a QP over ``x = (qacc, lambda)`` with ``lambda >= 0`` the weights of the edges of a
  linearised friction pyramid at each floor contact MuJoCo reports (feet within
  :attr:`TrackingSettings.contact_margin` of the floor count, so the whole sole is usable):

      min  |W (qacc - qacc_des)|² + w_f |J_rot qacc - a_f|² + w_c |J_c qacc + k_c J_c qvel|²
           + |W_com (J_com qacc - a_com)|² + w_lambda |lambda|²
      s.t. M_root qacc + c_root = (J_cᵀ E lambda)_root        (the 6 unactuated rows)

  so the root's acceleration can come from contact forces only; ``a_com = a_ref + Kp (c_ref -
  c) + Kd (v_ref - v)`` steers the whole-body centre of mass (``mj_jacSubtreeCom``; the
  reference's from ``subtree_com``, finite-differenced) — the centroidal (linear momentum)
  task of Wensing & Orin 2013, which only contact forces can satisfy;
* joint torques ``tau = (M qacc + c - J_cᵀ E lambda)_hinges`` are sent to the actuators,
  switched to motors in the tracking model copy; MuJoCo then simulates the contacts itself.
  The QP runs every :attr:`TrackingSettings.control_period` simulation steps (100 Hz by
  default) and its torques are held in between.

Foot placement (capture point, Pratt et al. 2006 "Capture point: a step toward humanoid push
recovery"; SIMBICON's ``c_d d + c_v v`` of Yin et al. 2007 is its linear form): a leg the
reference swings has its hip target shifted by ``J_hip⁺ (g ⊙ e_xi)``, with ``e_xi`` the
horizontal error of the capture point ``xi = c + v / omega`` (``omega = sqrt(g / c_z)``;
simulated minus reference, in world coordinates, gains ``g`` along the reference heading and
sideways) and ``J_hip`` the ankle's horizontal Jacobian over the hip hinges, so the next
stance foot lands where it can bring the body back onto the reference.

Timing (phase adaptation): the reference is played on its own clock, whose rate is ``1 +
k e_fwd`` (bounded), ``e_fwd`` the capture-point error along the heading. A body ahead of its
reference gets the reference's next steps sooner instead of being pulled back through its
stance foot, which the friction and the sole's size cannot always do (step-timing adaptation
of gait controllers, e.g. Khadiv et al. 2016 "Step timing adjustment: a step toward generating
robust gaits"). Errors and falls are judged against the reference at its clock.

Nothing acts on the root: no actuator on the free joint, ``xfrc_applied`` and
``qfrc_applied`` stay zero (tested). Only the floor collides with the body (limbs of
retargeted clips overlap, and forces between them would be unknown to the controller).

On its own the controller walks a few steps (built-in 4 s walks: a fall at 2.1-3.8 s or none;
one sampled subject fell at 1.3 s, tests/measurements/walk_spread.py; Bandai walks retargeted
with ``level_feet``: 2-3.2 s); :mod:`sim.sampling` searches over its targets for walks of 10 s
and more.

A fall (after Peng et al. 2018, DeepMimic, whose episodes end when the character falls) is
the first frame where the head is below :attr:`TrackingSettings.fall_head_ratio` of the
reference head height, or the root's up axis is tilted more than
:attr:`TrackingSettings.fall_tilt_deg` away from the reference root's. A body that stays up
but loses the reference, its body17 sites on average more than
:attr:`TrackingSettings.lost_error_m` from the reference's (the 0.5 m termination distance of
Luo et al. 2023, "Perpetual humanoid control"), has failed as well and counts as fallen there.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import mujoco
import numpy as np
from qpsolvers import solve_qp
from scipy.ndimage import gaussian_filter1d
from scipy.spatial.distance import cdist

from avatar_models.body17 import BODY17
from avatar_models.errors import MotionValueError
from sim.soles import (
    ANKLE_SITES,
    box_corners,
    corner_positions,
    foot_bodies,
    sole_boxes,
    thigh_bodies,
)

ROOT_DOF = 6
QP_SOLVER = "daqp"
GRAVITY = 9.81


@dataclass(frozen=True)
class TrackingSettings:
    """Controller gains, QP weights and fall criteria (accelerations in rad/s² or m/s²).

    Attributes:
        kp, kd: hinge stiffness (1/s²) and damping (1/s) of ``qacc_des``.
        kp_root, kd_root: the same for the root's 6 dofs.
        kp_root_xy: root stiffness along world X and Y (drift is corrected by stepping).
        root_weight: QP weight of the root rows relative to a hinge's 1.
        foot_weight, kp_foot, kd_foot: world-orientation task of each foot.
        contact_weight, contact_damping: ``|J_c qacc + k_c J_c qvel|²`` keeps a contact still.
        force_weight: regularisation of the friction-pyramid weights (1/N²).
        friction: cone coefficient of the QP, below the geoms' 1.0 for a margin.
        contact_margin: a foot within this of the floor (m) offers contacts to the QP.
        level_stance_feet: aim a foot the reference stands on flat (see ``_foot_tasks``).
        com_weight, kp_com, kd_com: centre-of-mass task, per axis (world x, y, z); weight next
            to a hinge's 1.
        capture_gain: foot-placement shift per metre of capture-point error (simulated minus
            reference), along the reference's heading and sideways.
        max_step_shift: bound on the foot-placement shift (m).
        clock_gain: reference clock rate change per metre of forward capture-point error
            (simulated minus reference): a body ahead of its reference plays the reference
            faster, one behind plays it slower (1/m).
        max_clock_change: bound on the clock rate's departure from 1.
        swing_ramp_s: the shift fades in over this time after lift-off.
        stance_height: a reference foot stands while its ankle is within this of its lowest
            height in the clip (m).
        smoothing_frames: Gaussian sigma (frames) on the reference velocities and
            accelerations (finite differences of mocap are noisy).
        control_period: simulation steps per controller update (torques held in between).
        fall_head_ratio: fall when head height < this x the reference head height.
        fall_tilt_deg: fall when the root's up axis is this far from the reference's.
        lost_error_m: fall (lost) when the mean body17 distance from the reference is larger.
    """

    kp: float = 400.0
    kd: float = 40.0
    kp_root: float = 50.0
    kp_root_xy: float = 0.0
    kd_root: float = 20.0
    root_weight: float = 3.0
    foot_weight: float = 30.0
    kp_foot: float = 400.0
    kd_foot: float = 40.0
    contact_weight: float = 100.0
    contact_damping: float = 20.0
    force_weight: float = 1e-6
    friction: float = 0.8
    contact_margin: float = 0.005
    level_stance_feet: bool = False
    com_weight: tuple[float, float, float] = (3.0, 3.0, 3.0)
    kp_com: float = 20.0
    kd_com: float = 10.0
    capture_gain: tuple[float, float] = (0.2, 0.5)
    max_step_shift: float = 0.25
    clock_gain: float = 2.0
    max_clock_change: float = 0.2
    swing_ramp_s: float = 0.15
    stance_height: float = 0.03
    smoothing_frames: float = 1.0
    control_period: int = 5
    fall_head_ratio: float = 0.6
    fall_tilt_deg: float = 60.0
    lost_error_m: float = 0.5


@dataclass(frozen=True)
class TrackingResult:
    """What the simulated humanoid did.

    Attributes:
        qpos: ``(T, nq)`` simulated configuration at each reference frame.
        body17_error: ``(T, 17)`` distance (metres) of each body17 site from the reference.
        torque: ``(T, nu)`` actuator torques (N m) at each frame.
        power: ``(T,)`` mechanical power sum |tau * qd| over the hinges (W).
        fall_frame: first frame judged fallen (or lost, module docstring), or ``None``.
        fps: reference frame rate.
        reference_frame: ``(T,)`` the (fractional) reference frame played at each frame
            (:attr:`TrackingSettings.clock_gain`); errors and falls are judged against it.
    """

    qpos: np.ndarray
    body17_error: np.ndarray
    torque: np.ndarray
    power: np.ndarray
    fall_frame: int | None
    fps: float
    reference_frame: np.ndarray

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


def forward_differences(model: mujoco.MjModel, qpos: np.ndarray, fps: float) -> np.ndarray:
    """``(T, nv)`` velocity from each frame to the next (the last repeats the one before),
    on the manifold (``mj_differentiatePos``, so the root quaternion is handled)."""
    n = qpos.shape[0]
    forward = np.zeros((n, model.nv))
    for t in range(n - 1):  # one MuJoCo call per frame pair
        mujoco.mj_differentiatePos(model, forward[t], 1.0 / fps, qpos[t], qpos[t + 1])
    if n > 1:
        forward[-1] = forward[-2]
    return forward


def reference_velocities(model: mujoco.MjModel, qpos: np.ndarray, fps: float) -> np.ndarray:
    """``(T, nv)`` velocities of ``qpos (T, nq)`` by central differences on the manifold."""
    forward = forward_differences(model, qpos, fps)
    return 0.5 * (forward + np.vstack([forward[:1], forward[:-1]]))


def looped(qpos: np.ndarray, fps: float, duration_s: float, min_cycle_s: float = 0.8):
    """``(T', nq)`` the clip ``qpos (T, nq)`` played once, then its best gait cycle repeated
    until it lasts ``duration_s``.

    The cycle is the frame pair ``i < j`` (``j - i >= min_cycle_s``) whose hinge angles and
    hinge velocities match best; each repetition of frames ``[i, j)`` is moved by the
    horizontal rigid motion (yaw about Z, translation in XY) that takes the root at ``i`` to
    the root at ``j``, so the walk continues where it left off.
    """
    n, need = qpos.shape[0], int(np.ceil(duration_s * fps)) + 1
    if n >= need:
        return qpos[:need]
    if n < 3:
        raise MotionValueError(f"clip too short to loop: {n} frames at {fps} fps")
    hinge = qpos[:, 7:]
    feature = np.hstack([hinge, np.gradient(hinge, axis=0) * 3.0, qpos[:, 2:3] * 10.0])
    dist = cdist(feature, feature)  # (T, T); a broadcast difference would be (T, T, F)
    gap = np.arange(n)[None] - np.arange(n)[:, None]
    dist[gap < min_cycle_s * fps] = np.inf
    i, j = np.unravel_index(np.argmin(dist), dist.shape)
    if not np.isfinite(dist[i, j]):
        raise MotionValueError(f"clip too short to loop: {n} frames at {fps} fps")
    turn = _yaw(qpos[j, 3:7]) - _yaw(qpos[i, 3:7])
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    pieces = [qpos[:j]]
    repeat = qpos[i:j].copy()
    for _ in range(int(np.ceil((need - j) / (j - i)))):
        repeat = repeat.copy()
        repeat[:, :2] = (repeat[:, :2] - qpos[i, :2]) @ rot.T + qpos[j, :2]
        repeat[:, 3:7] = _yaw_quat(turn, repeat[:, 3:7])
        pieces.append(repeat)
    return np.vstack(pieces)[:need]


def _yaw(q: np.ndarray) -> float:
    """Heading (rad) of the root's local +X for a wxyz quaternion."""
    w, x, y, z = q
    return float(np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


def _heading(q: np.ndarray) -> np.ndarray:
    """``(2, 2)`` rotation taking world horizontal vectors to (forward, left) of the heading
    of configuration ``q (nq,)``."""
    yaw = _yaw(q[3:7])
    return np.array([[np.cos(yaw), np.sin(yaw)], [-np.sin(yaw), np.cos(yaw)]])


def _yaw_quat(angle: float, quats: np.ndarray) -> np.ndarray:
    """``(T, 4)`` ``quats`` turned by ``angle`` about world Z (wxyz)."""
    turn = np.array([np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)])
    out = np.empty_like(quats)
    for t in range(quats.shape[0]):  # mju_mulQuat is one quaternion per call
        mujoco.mju_mulQuat(out[t], turn, quats[t])
    return out


@dataclass(frozen=True)
class Reference:
    """A reference motion prepared for tracking (:meth:`Tracker.reference`).

    Attributes:
        qpos: ``(T, nq)`` configurations at ``fps``.
        forward: ``(T, nv)`` velocity from each frame to the next (interpolation).
        qvel, qacc: ``(T, nv)`` smoothed velocities and accelerations.
        swing: ``(T, 2)`` foot-placement weights (:meth:`Tracker.swing_weights`).
        sites: ``(T, 17, 3)`` body17 site positions.
        com: ``(T, 3, 3)`` whole-body centre of mass position, velocity, acceleration.
    """

    qpos: np.ndarray
    forward: np.ndarray
    qvel: np.ndarray
    qacc: np.ndarray
    swing: np.ndarray
    sites: np.ndarray
    com: np.ndarray
    fps: float


@dataclass(frozen=True)
class Progress:
    """The controller's state between simulation steps (MuJoCo's own state is in ``data``).

    Attributes:
        step: simulation steps taken.
        clock: reference frame (fractional) played now; ``rate`` its frames per frame.
        tau: ``(nu,)`` torques held until the next control update.
        frames: one record per reference frame so far (:meth:`Tracker._frame_record`).
    """

    step: int
    clock: float
    rate: float
    tau: np.ndarray
    frames: list


class Tracker:
    """A simulation of ``model`` (the humanoid MJCF) tracking references. See the module
    docstring for the controller. ``data`` is exposed so callers can inspect the state."""

    def __init__(self, model: mujoco.MjModel, settings: TrackingSettings | None = None):
        if model.nu == 0 or np.any(model.jnt_type[model.actuator_trnid[:, 0]] == 0):
            raise MotionValueError("tracking needs hinge actuators and no actuator on the root")
        self.settings = s = settings or TrackingSettings()
        # A copy: the caller's model (e.g. a Humanoid's, shared by every stage) stays as is.
        self.model = model = copy.copy(model)
        # The tracking copy's actuators become motors (ctrl = torque, no clamp), and geoms
        # report floor contacts within the margin without acting on them (gap = margin).
        model.actuator_gainprm[:] = 0.0
        model.actuator_gainprm[:, 0] = 1.0
        model.actuator_biasprm[:] = 0.0
        model.actuator_ctrllimited[:] = 0
        # Only the floor collides with the body: the retargeted limbs of real clips overlap
        # (upper arms 4 cm into the chest, calves crossing), and contacts between them would
        # push with forces the controller does not know of. Self-collision is a check on the
        # reference (sim.checks.self_collision), not something to simulate while tracking.
        world = model.geom_bodyid == 0
        model.geom_contype[:] = np.where(world, 0, 1)
        model.geom_conaffinity[:] = np.where(world, 1, 0)
        self.data = mujoco.MjData(model)
        self.dof = model.jnt_dofadr[model.actuator_trnid[:, 0]]
        self.hinge_qadr = model.jnt_qposadr[model.actuator_trnid[:, 0]]
        self.sites = np.array(
            [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, n) for n in BODY17]
        )
        self.ankles = np.array(
            [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, n) for n in ANKLE_SITES]
        )
        self.feet = [model.body(name).id for name in foot_bodies(model)]
        hips = [
            np.flatnonzero(model.jnt_bodyid == model.body(name).id) for name in thigh_bodies(model)
        ]
        self.hip_dof = [model.jnt_dofadr[j] for j in hips]
        self.hip_qadr = [model.jnt_qposadr[j] for j in hips]
        # Sole boxes: the box geoms of the feet and the bodies below them (toes), with their
        # 8 corners in the geom frame (the lowest ones are the sole's).
        self.sole_geoms = sole_boxes(model)
        if self.sole_geoms.size == 0:
            raise MotionValueError("tracking needs box feet (the sole corners are contacts)")
        self.sole_corners = box_corners(model, self.sole_geoms)  # (G, 8, 3)
        nv = model.nv
        self.kp = np.full(nv, s.kp)
        self.kd = np.full(nv, s.kd)
        self.kp[:ROOT_DOF], self.kd[:ROOT_DOF] = s.kp_root, s.kd_root
        self.kp[:2] = s.kp_root_xy
        self.weight = np.ones(nv)
        self.weight[:ROOT_DOF] = s.root_weight
        rest = mujoco.MjData(model)
        mujoco.mj_kinematics(model, rest)  # qpos0 stands flat-footed on the floor
        self.sole_normal = [rest.xmat[b].reshape(3, 3)[2] for b in self.feet]  # R^T z
        mu = s.friction
        # Friction-pyramid edges on the floor, world axes (x, y, z) by edge.
        self._jac_com = np.zeros((3, nv))
        self.edges = np.array([[mu, 0, 1], [-mu, 0, 1], [0, mu, 1], [0, -mu, 1]], float).T

    def swing_weights(self, qpos: np.ndarray, fps: float) -> np.ndarray:
        """``(T, 2)`` 0..1 weight of the foot-placement shift per leg (left, right): 0 while
        the reference foot stands, ramping to 1 over ``swing_ramp_s`` after lift-off."""
        ankles = self._site_positions(qpos, self.ankles)[..., 2]
        swing = ankles >= ankles.min(axis=0) + self.settings.stance_height
        since = np.zeros(swing.shape)
        for t in range(1, swing.shape[0]):  # a running count: sequential by definition
            since[t] = np.where(swing[t], since[t - 1] + 1.0 / fps, 0.0)
        ramp = max(self.settings.swing_ramp_s, 1e-9)
        return np.where(swing, np.clip(since / ramp, 1.0 / (ramp * fps), 1.0), 0.0)

    def reference_com(self, qpos: np.ndarray) -> np.ndarray:
        """``(T, 3)`` whole-body centre of mass of ``qpos (T, nq)``."""
        data = mujoco.MjData(self.model)
        out = np.empty((qpos.shape[0], 3))
        for t in range(qpos.shape[0]):  # MuJoCo evaluates one state per call
            data.qpos[:] = qpos[t]
            mujoco.mj_kinematics(self.model, data)
            mujoco.mj_comPos(self.model, data)
            out[t] = data.subtree_com[0]
        return out

    def reference_sites(self, qpos: np.ndarray) -> np.ndarray:
        """``(T, 17, 3)`` body17 site positions of ``qpos (T, nq)`` (kinematics only)."""
        return self._site_positions(qpos, self.sites)

    def _site_positions(self, qpos: np.ndarray, sites: np.ndarray) -> np.ndarray:
        data = mujoco.MjData(self.model)
        out = np.empty((qpos.shape[0], sites.size, 3))
        for t in range(qpos.shape[0]):  # MuJoCo evaluates one state per call
            data.qpos[:] = qpos[t]
            mujoco.mj_kinematics(self.model, data)
            out[t] = data.site_xpos[sites]
        return out

    def reference(self, qpos_ref: np.ndarray, fps: float) -> Reference:
        """Precompute what the controller needs of ``qpos_ref (T, nq)`` sampled at ``fps``."""
        qpos_ref = np.asarray(qpos_ref, dtype=float)
        m, s = self.model, self.settings
        if qpos_ref.ndim != 2 or qpos_ref.shape[1] != m.nq or not np.isfinite(qpos_ref).all():
            raise MotionValueError(f"reference must be finite (T, {m.nq}), got {qpos_ref.shape}")
        if qpos_ref.shape[0] < 2:
            raise MotionValueError("reference must have at least 2 frames")
        qvel = reference_velocities(m, qpos_ref, fps)
        sigma = s.smoothing_frames
        if sigma > 0:
            qvel = gaussian_filter1d(qvel, sigma, axis=0, mode="nearest")
        qacc = np.gradient(qvel, 1.0 / fps, axis=0)
        if sigma > 0:
            qacc = gaussian_filter1d(qacc, sigma, axis=0, mode="nearest")
        return Reference(
            qpos=qpos_ref,
            forward=forward_differences(m, qpos_ref, fps),
            qvel=qvel,
            qacc=qacc,
            swing=self.swing_weights(qpos_ref, fps),
            sites=self.reference_sites(qpos_ref),
            com=_with_derivatives(self.reference_com(qpos_ref), fps),
            fps=fps,
        )

    def start(self, ref: Reference) -> Progress:
        """Put the humanoid on the reference's first frame and velocity; the controller's
        state at that moment (frame 0 recorded)."""
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        d.qpos[:], d.qvel[:] = ref.qpos[0], ref.qvel[0]
        mujoco.mj_step1(m, d)
        self._ref_data = mujoco.MjData(m)
        progress = Progress(step=0, clock=0.0, rate=1.0, tau=np.zeros(m.nu), frames=[])
        progress.frames.append(self._frame_record(0.0))
        return progress

    def steps_of(self, ref: Reference) -> int:
        """Simulation steps that cover the reference's duration."""
        n = ref.qpos.shape[0]
        return int(np.ceil((n - 1) / (ref.fps * self.model.opt.timestep) - 1e-9))

    def advance(
        self,
        ref: Reference,
        progress: Progress,
        steps: int,
        target_offset: np.ndarray | None = None,
    ) -> Progress:
        """Simulate ``steps`` more steps from the current state; ``progress`` is the
        controller's state there, the returned one is its state after (with the frames
        recorded on the way). ``target_offset (nu,)`` (radians) is added to every actuated
        hinge's target (:mod:`sim.sampling` searches over it)."""
        m, d, s = self.model, self.data, self.settings
        n, fps, dt = ref.qpos.shape[0], ref.fps, m.opt.timestep
        q_target = np.empty(m.nq)
        clock, rate, tau = progress.clock, progress.rate, progress.tau.copy()
        frames = []
        last = min(progress.step + steps, self.steps_of(ref))
        for k in range(progress.step, last):  # the simulation is sequential by nature
            if k % s.control_period == 0:
                phase = min(clock, n - 1.0)
                i = min(int(phase), n - 2)
                a = min(phase - i, 1.0)
                q_target[:] = ref.qpos[i]
                mujoco.mj_integratePos(m, q_target, ref.forward[i], a / fps)
                v_target = (1 - a) * ref.qvel[i] + a * ref.qvel[i + 1]
                a_target = (1 - a) * ref.qacc[i] + a * ref.qacc[i + 1]
                swinging = (1 - a) * ref.swing[i] + a * ref.swing[i + 1]
                com = (1 - a) * ref.com[i] + a * ref.com[i + 1]
                self._com_jacobian()
                error = self._capture_error(q_target, com)
                bound = s.max_clock_change
                rate = 1.0 + np.clip(s.clock_gain * error[0], -bound, bound)
                self._place_feet(q_target, self._step_shift(q_target, error), swinging)
                if target_offset is not None:
                    q_target[self.hinge_qadr] += target_offset
                standing = (swinging == 0) & s.level_stance_feet
                tau = self._torques(q_target, v_target, a_target, com, standing)
            d.ctrl[:] = tau
            mujoco.mj_step2(m, d)
            mujoco.mj_step1(m, d)
            clock += rate * dt * fps
            t_prev, t = int(np.floor(k * dt * fps + 1e-9)), int(np.floor((k + 1) * dt * fps + 1e-9))
            if t < n and t != t_prev:
                frames.append(self._frame_record(min(clock, n - 1.0)))
        return Progress(step=last, clock=clock, rate=rate, tau=tau, frames=progress.frames + frames)

    def finished(self, ref: Reference, progress: Progress) -> bool:
        return progress.step >= self.steps_of(ref)

    def result(self, ref: Reference, frames: list[tuple]) -> TrackingResult:
        """The :class:`TrackingResult` of the recorded ``frames`` (one per reference frame)."""
        columns = zip(*frames, strict=True)
        reference_frame, qpos, sites, torque, power, unstable = (np.array(c) for c in columns)
        ref_sites = _at_frames(ref.sites, reference_frame)
        qpos_ref = ref.qpos[np.round(reference_frame).astype(int)]
        return TrackingResult(
            qpos=qpos,
            body17_error=np.linalg.norm(sites - ref_sites, axis=-1),
            torque=torque,
            power=power,
            fall_frame=self._fall_frame(qpos, qpos_ref, sites, ref_sites, unstable),
            fps=ref.fps,
            reference_frame=reference_frame,
        )

    def run(self, qpos_ref: np.ndarray, fps: float) -> TrackingResult:
        """Track ``qpos_ref (T, nq)`` sampled at ``fps`` from its first frame and velocity.
        The reference is interpolated at every control update (on the manifold)."""
        ref = self.reference(qpos_ref, fps)
        progress = self.advance(ref, self.start(ref), self.steps_of(ref))
        return self.result(ref, progress.frames)

    def _frame_record(self, reference_frame: float) -> tuple:
        """What is kept of the current state at a reference frame."""
        d = self.data
        power = np.abs(d.actuator_force * d.qvel[self.dof]).sum()
        return (
            reference_frame,
            d.qpos.copy(),
            d.site_xpos[self.sites].copy(),
            d.actuator_force.copy(),
            power,
            self.unstable(),
        )

    def restore(self, state: np.ndarray, spec: int) -> None:
        """Put the simulation back into ``state`` (``mj_getState`` with ``spec``), warnings
        cleared, ready for :meth:`advance`."""
        mujoco.mj_setState(self.model, self.data, state, spec)
        for warning in self.data.warning:
            warning.number = 0
        mujoco.mj_step1(self.model, self.data)

    def unstable(self) -> bool:
        """Whether MuJoCo has met a diverging acceleration or torque since the start. It then
        resets the state to the model's rest pose and goes on, so the rest of the run is no
        tracking at all: it counts as a fall from that frame on (:meth:`restore` clears it)."""
        warnings = self.data.warning
        return bool(
            warnings[mujoco.mjtWarning.mjWARN_BADQACC].number
            or warnings[mujoco.mjtWarning.mjWARN_BADCTRL].number
        )

    def _com_jacobian(self):
        """``(3, nv)`` Jacobian of the whole-body centre of mass in the current state."""
        mujoco.mj_jacSubtreeCom(self.model, self.data, self._jac_com, 0)

    def _capture_error(self, q_target: np.ndarray, com: list[np.ndarray]) -> np.ndarray:
        """``(2,)`` horizontal capture-point error, simulated minus reference, along the
        reference heading and to its left (m). ``com``: reference centre of mass position,
        velocity, acceleration ``(3,)`` each."""
        d = self.data
        omega = np.sqrt(GRAVITY / com[0][2])
        capture = d.subtree_com[0, :2] + (self._jac_com @ d.qvel)[:2] / omega
        return _heading(q_target) @ (capture - com[0][:2] - com[1][:2] / omega)

    def _step_shift(self, q_target: np.ndarray, error: np.ndarray) -> np.ndarray:
        """``(2,)`` world shift of a swinging foot's target: the capture-point ``error (2,)``
        (:meth:`_capture_error`) times :attr:`TrackingSettings.capture_gain`, bounded by
        ``max_step_shift``."""
        s = self.settings
        shift = _heading(q_target).T @ (np.asarray(s.capture_gain) * error)
        norm = np.linalg.norm(shift)
        if norm > s.max_step_shift:
            shift *= s.max_step_shift / norm
        return shift

    def _place_feet(self, q_target: np.ndarray, shift: np.ndarray, swing: np.ndarray):
        """Shift the swinging hips' targets in ``q_target`` (in place) so that the ankles
        move by ``swing (2,) x shift (2,)`` (world, horizontal): ``J_hip⁺ shift`` with the
        ankle's horizontal Jacobian over the hip hinges (damped pseudo-inverse)."""
        jac = np.zeros((3, self.model.nv))
        for side in np.flatnonzero(swing > 0):
            mujoco.mj_jacSite(self.model, self.data, jac, None, self.ankles[side])
            j = jac[:2, self.hip_dof[side]]
            dq = j.T @ np.linalg.solve(j @ j.T + 1e-4 * np.eye(2), shift)
            q_target[self.hip_qadr[side]] += swing[side] * dq

    def _torques(self, q_target, v_target, a_target, com, standing) -> np.ndarray:
        """``(nu,)`` hinge torques of the whole-body QP (module docstring)."""
        m, d, s = self.model, self.data, self.settings
        nv = m.nv
        error = np.empty(nv)
        mujoco.mj_differentiatePos(m, error, 1.0, d.qpos, q_target)
        qacc_des = a_target + self.kp * error + self.kd * (v_target - d.qvel)
        mass = np.empty((nv, nv))
        mujoco.mj_fullM(m, d, mass)
        bias = d.qfrc_bias
        jc, je = self._contacts()
        nx = nv + je.shape[1]
        hess = np.zeros((nx, nx))
        grad = np.zeros(nx)
        hess[:nv, :nv] = np.diag(self.weight)
        grad[:nv] = -self.weight * qacc_des
        for jr, acc in self._foot_tasks(q_target, v_target, standing):
            hess[:nv, :nv] += s.foot_weight * jr.T @ jr
            grad[:nv] -= s.foot_weight * jr.T @ acc
        jcom, wcom = self._jac_com, np.asarray(s.com_weight)[:, None]
        com_acc = (
            com[2] + s.kp_com * (com[0] - d.subtree_com[0]) + s.kd_com * (com[1] - jcom @ d.qvel)
        )
        hess[:nv, :nv] += jcom.T @ (wcom * jcom)
        grad[:nv] -= jcom.T @ (wcom[:, 0] * com_acc)
        if je.shape[1]:
            hess[:nv, :nv] += s.contact_weight * jc.T @ jc
            grad[:nv] += s.contact_weight * jc.T @ (s.contact_damping * (jc @ d.qvel))
            hess[nv:, nv:] = s.force_weight * np.eye(je.shape[1])
        eq = np.hstack([mass[:ROOT_DOF], -je[:ROOT_DOF]])
        lower = np.full(nx, -np.inf)
        lower[nv:] = 0.0
        x = solve_qp(hess, grad, A=eq, b=-bias[:ROOT_DOF], lb=lower, solver=QP_SOLVER)
        if x is None:  # no solution: hold the pose with gravity compensation only
            x = np.concatenate([np.zeros(nv), np.zeros(je.shape[1])])
        generalised = mass @ x[:nv] + bias - je @ x[nv:]
        return generalised[self.dof]

    def _contacts(self) -> tuple[np.ndarray, np.ndarray]:
        """``(3C, nv)`` Jacobian of the candidate floor contacts and ``(nv, 4C)`` generalised
        forces of their friction-pyramid edges (world frame: the floor's normal is +Z).

        The candidates are the corners of the sole boxes that are within
        :attr:`TrackingSettings.contact_margin` of the floor, not MuJoCo's reported contacts:
        on one foot MuJoCo often reports 1-3 points, which leaves the QP a support polygon
        too small to push the body sideways; the corners span the whole sole."""
        m, d = self.model, self.data
        corners = corner_positions(d, self.sole_geoms, self.sole_corners)
        in_contact = np.zeros(m.ngeom, bool)
        in_contact[d.contact.geom[: d.ncon].ravel()] = True  # MuJoCo's contacts
        touching = in_contact[self.sole_geoms]
        near = (corners[..., 2] < self.settings.contact_margin) & touching[:, None]  # (G, 8)
        geom, corner = np.nonzero(near)
        points = corners[geom, corner]
        jc = np.empty((3 * points.shape[0], m.nv))
        for n, (point, g) in enumerate(zip(points, self.sole_geoms[geom], strict=True)):
            mujoco.mj_jac(m, d, jc[3 * n : 3 * n + 3], None, point, m.geom_bodyid[g])
        je = np.einsum("cin,ie->nce", jc.reshape(-1, 3, m.nv), self.edges)
        return jc, je.reshape(m.nv, -1)

    def _foot_tasks(self, q_target, v_target, standing):
        """Per foot: ``(3, nv)`` rotational Jacobian and the desired angular acceleration
        towards the reference foot's orientation, levelled (sole normal turned onto +Z by
        the smallest rotation) while the reference stands on it: retargeted clips often
        stand on a tilted sole, which would leave one edge of the foot on the floor."""
        m, d, s, ref = self.model, self.data, self.settings, self._ref_data
        ref.qpos[:] = q_target
        mujoco.mj_kinematics(m, ref)
        mujoco.mj_comPos(m, ref)
        jr, jr_ref = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        conj, err_quat, err = np.empty(4), np.empty(4), np.empty(3)
        target, level = np.empty(4), np.empty(4)
        for body, normal, stand in zip(self.feet, self.sole_normal, standing, strict=True):
            mujoco.mj_jacBody(m, d, None, jr, body)
            mujoco.mj_jacBody(m, ref, None, jr_ref, body)
            target[:] = ref.xquat[body]
            if stand:
                mujoco.mju_quatZ2Vec(level, ref.xmat[body].reshape(3, 3) @ normal)
                mujoco.mju_negQuat(level, level)
                mujoco.mju_mulQuat(target, level, ref.xquat[body])
            mujoco.mju_negQuat(conj, d.xquat[body])
            mujoco.mju_mulQuat(err_quat, target, conj)
            mujoco.mju_quat2Vel(err, err_quat, 1.0)
            yield jr.copy(), s.kp_foot * err + s.kd_foot * (jr_ref @ v_target - jr @ d.qvel)

    def fallen(self, qpos, qpos_ref, sites, ref_sites, unstable) -> np.ndarray:
        """``(T,)`` whether each frame is fallen or lost (module docstring): ``qpos`` and
        ``qpos_ref (T, nq)``, body17 ``sites`` and ``ref_sites (T, 17, 3)``, ``unstable (T,)``
        (:meth:`unstable`)."""
        s, head = self.settings, BODY17.index("head")
        low = sites[:, head, 2] < s.fall_head_ratio * ref_sites[:, head, 2]
        tilt = np.degrees(np.arccos(np.clip(np.sum(_up(qpos) * _up(qpos_ref), -1), -1, 1)))
        lost = np.linalg.norm(sites - ref_sites, axis=-1).mean(axis=1) > s.lost_error_m
        return low | (tilt > s.fall_tilt_deg) | unstable | lost

    def _fall_frame(self, qpos, qpos_ref, sites, ref_sites, unstable) -> int | None:
        fallen = np.flatnonzero(self.fallen(qpos, qpos_ref, sites, ref_sites, unstable))
        return int(fallen[0]) if fallen.size else None


def _with_derivatives(x: np.ndarray, fps: float) -> np.ndarray:
    """``(T, 3, ...)`` ``x (T, ...)``, its velocity and acceleration (central differences,
    each smoothed by a 1-frame Gaussian: finite differences of mocap are noisy)."""
    vel = gaussian_filter1d(np.gradient(x, 1.0 / fps, axis=0), 1.0, axis=0)
    acc = gaussian_filter1d(np.gradient(vel, 1.0 / fps, axis=0), 1.0, axis=0)
    return np.stack([x, vel, acc], axis=1)


def _at_frames(values: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """``values (T, ...)`` linearly interpolated at fractional frame indices ``frames (T',)``
    (within ``[0, T - 1]``)."""
    i = np.minimum(frames.astype(int), values.shape[0] - 2)
    a = (frames - i).reshape(-1, *([1] * (values.ndim - 1)))
    return (1 - a) * values[i] + a * values[i + 1]


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
    """Track ``qpos_ref (T, nq)`` at ``fps`` with a fresh :class:`Tracker` on a copy of
    ``model``."""
    return Tracker(model, settings).run(qpos_ref, fps)
