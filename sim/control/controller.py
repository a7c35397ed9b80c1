"""The controller: the humanoid follows a reference ``qpos`` under simulation, root unactuated.

Every :attr:`ControlSettings.control_period` simulation steps (100 Hz by default) it reads the
reference at its clock (:meth:`sim.control.reference.Reference.at`), shifts the swinging
feet's targets and sets the clock's rate from the capture point (:mod:`sim.control.balance`),
and computes torques with the whole-body QP (:mod:`sim.control.qp`), held until the next
update. Errors and falls (:mod:`sim.control.falls`) are judged against the reference at its
clock.

Nothing acts on the root: no actuator on the free joint, ``xfrc_applied`` and
``qfrc_applied`` stay zero (tested). Only the floor collides with the body
(:func:`sim.control.model.control_model`).

On its own the controller walks a few steps (built-in 4 s walks: a fall at 2.1-3.8 s or none;
one sampled subject fell at 1.3 s, tests/measurements/walk_spread.py; Bandai walks retargeted
with ``level_feet``: 2-3.2 s); :mod:`sim.control.search` searches over its targets for walks of
10 s and more.

Shapes: ``T`` reference frames, ``nq``/``nv``/``nu`` MuJoCo sizes, 17 body17 sites.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.sim.control import balance
from avatarsim.sim.control.falls import fallen, first_fall
from avatarsim.sim.control.model import BodyIndices, is_control_model
from avatarsim.sim.control.qp import WholeBodyQP
from avatarsim.sim.control.records import FrameRecord, Recording
from avatarsim.sim.control.reference import Reference, ReferencePoint
from avatarsim.sim.control.settings import ControlSettings


@dataclass(frozen=True)
class ControlResult:
    """What the simulated humanoid did.

    Attributes:
        qpos: ``(T, nq)`` simulated configuration at each reference frame.
        body17_error: ``(T, 17)`` distance (metres) of each body17 site from the reference.
        torque: ``(T, nu)`` actuator torques (N m) at each frame.
        power: ``(T,)`` mechanical power sum |tau * qd| over the hinges (W).
        fall_frame: first frame judged fallen (or lost, :mod:`sim.control.falls`), or
            ``None``.
        fps: reference frame rate.
        reference_frame: ``(T,)`` the (fractional) reference frame played at each frame
            (:attr:`ControlSettings.clock_gain`); errors and falls are judged against it.
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


@dataclass(frozen=True)
class Progress:
    """The controller's state between simulation steps (MuJoCo's own state is in ``data``).

    Attributes:
        step: simulation steps taken.
        clock: reference frame (fractional) played now; ``rate`` its frames per frame.
        tau: ``(nu,)`` torques held until the next control update.
        recording: one record per reference frame so far.
    """

    step: int
    clock: float
    rate: float
    tau: np.ndarray
    recording: Recording


class Controller:
    """A simulation of the humanoid following references (module docstring). ``model`` is
    the humanoid's control variant (:func:`sim.control.model.control_model`, or
    :meth:`sim.humanoid.Humanoid.control_model`), compiled once and only read here: several
    controllers may share it. ``data`` is this simulation's, exposed for inspection."""

    def __init__(self, model: mujoco.MjModel, settings: ControlSettings | None = None):
        if not is_control_model(model):
            raise MotionValueError(
                "Controller needs the humanoid's control variant (motors, floor contacts): "
                "pass avatarsim.sim.control.model.control_model(spec) or Humanoid.control_model()"
            )
        self.settings = settings or ControlSettings()
        self.model = model
        self.data = mujoco.MjData(self.model)
        self.body = BodyIndices.of(self.model)
        self.qp = WholeBodyQP(self.model, self.data, self.body, self.settings)
        self._jac_com = np.zeros((3, self.model.nv))

    def reference(self, qpos_ref: np.ndarray, fps: float) -> Reference:
        """``qpos_ref (T, nq)`` sampled at ``fps``, prepared for :meth:`advance`."""
        return Reference.build(self.model, self.body, qpos_ref, fps, self.settings)

    def start(self, ref: Reference) -> Progress:
        """Put the humanoid on the reference's first frame and velocity; the controller's
        state at that moment (frame 0 recorded)."""
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        d.qpos[:], d.qvel[:] = ref.qpos[0], ref.qvel[0]
        mujoco.mj_step1(m, d)
        first = Recording().then([self._frame_record(0.0)])
        return Progress(step=0, clock=0.0, rate=1.0, tau=np.zeros(m.nu), recording=first)

    def steps_of(self, ref: Reference) -> int:
        """Simulation steps that cover the reference's duration."""
        return int(np.ceil((ref.n_frames - 1) / (ref.fps * self.model.opt.timestep) - 1e-9))

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
        hinge's target (:mod:`sim.control.search` searches over it)."""
        m, d, s = self.model, self.data, self.settings
        n, fps, dt = ref.n_frames, ref.fps, m.opt.timestep
        clock, rate, tau = progress.clock, progress.rate, progress.tau.copy()
        records = []
        last = min(progress.step + steps, self.steps_of(ref))
        for k in range(progress.step, last):  # the simulation is sequential by nature
            if k % s.control_period == 0:
                point = ref.at(clock)
                error = self.capture_error(point.qpos, point.com)
                rate = balance.clock_rate(error, s)
                tau = self._torques(point, error, target_offset)
            d.ctrl[:] = tau
            mujoco.mj_step2(m, d)
            mujoco.mj_step1(m, d)
            clock += rate * dt * fps
            t_prev, t = int(np.floor(k * dt * fps + 1e-9)), int(np.floor((k + 1) * dt * fps + 1e-9))
            if t < n and t != t_prev:
                records.append(self._frame_record(min(clock, n - 1.0)))
        recording = progress.recording.then(records)
        return Progress(step=last, clock=clock, rate=rate, tau=tau, recording=recording)

    def _torques(
        self, point: ReferencePoint, error: np.ndarray, target_offset: np.ndarray | None
    ) -> np.ndarray:
        """``(nu,)`` the QP's torques towards ``point``, swinging feet placed for the
        capture-point ``error (2,)``, hinge targets moved by ``target_offset``."""
        q_target = point.qpos
        shift = balance.step_shift(q_target, error, self.settings)
        balance.place_feet(self.model, self.data, self.body, q_target, shift, point.swing)
        if target_offset is not None:
            q_target[self.body.hinge_qadr] += target_offset
        standing = (point.swing == 0) & self.settings.level_stance_feet
        return self.qp.torques(q_target, point.qvel, point.qacc, point.com, self._jac_com, standing)

    def finished(self, ref: Reference, progress: Progress) -> bool:
        return progress.step >= self.steps_of(ref)

    def result(self, ref: Reference, recording: Recording) -> ControlResult:
        """The :class:`ControlResult` of ``recording`` (one record per reference frame)."""
        c = recording.columns()
        reference_frame, qpos, sites = c["reference_frame"], c["qpos"], c["sites"]
        ref_sites = ref.sites_at(reference_frame)
        qpos_ref = ref.frame_qpos(reference_frame)
        fall = first_fall(fallen(self.settings, qpos, qpos_ref, sites, ref_sites, c["unstable"]))
        return ControlResult(
            qpos=qpos,
            body17_error=np.linalg.norm(sites - ref_sites, axis=-1),
            torque=c["torque"],
            power=c["power"],
            fall_frame=fall,
            fps=ref.fps,
            reference_frame=reference_frame,
        )

    def run(self, qpos_ref: np.ndarray, fps: float) -> ControlResult:
        """Follow ``qpos_ref (T, nq)`` sampled at ``fps`` from its first frame and velocity.
        The reference is interpolated at every control update (on the manifold)."""
        ref = self.reference(qpos_ref, fps)
        progress = self.advance(ref, self.start(ref), self.steps_of(ref))
        return self.result(ref, progress.recording)

    def _frame_record(self, reference_frame: float) -> FrameRecord:
        """What is kept of the current state at a reference frame."""
        d = self.data
        return FrameRecord(
            reference_frame=reference_frame,
            qpos=d.qpos.copy(),
            sites=d.site_xpos[self.body.sites].copy(),
            torque=d.actuator_force.copy(),
            power=np.abs(d.actuator_force * d.qvel[self.body.dof]).sum(),
            unstable=self.unstable(),
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
        control at all: it counts as a fall from that frame on (:meth:`restore` clears it)."""
        warnings = self.data.warning
        return bool(
            warnings[mujoco.mjtWarning.mjWARN_BADQACC].number
            or warnings[mujoco.mjtWarning.mjWARN_BADCTRL].number
        )

    def capture_error(self, qpos_ref: np.ndarray, com_ref: np.ndarray) -> np.ndarray:
        """``(2,)`` horizontal capture-point error of the current state, simulated minus
        reference, along the heading of ``qpos_ref (nq,)`` and to its left (m); ``com_ref
        (3, 3)`` the reference's centre of mass position, velocity, acceleration
        (:func:`sim.control.balance.capture_error`). Updates the centre-of-mass Jacobian the
        next torques use."""
        mujoco.mj_jacSubtreeCom(self.model, self.data, self._jac_com, 0)
        return balance.capture_error(self.data, self._jac_com, qpos_ref, com_ref)


def control(
    model: mujoco.MjModel,
    qpos_ref: np.ndarray,
    fps: float,
    settings: ControlSettings | None = None,
) -> ControlResult:
    """Follow ``qpos_ref (T, nq)`` at ``fps`` with a fresh :class:`Controller` on ``model``
    (the humanoid's control variant, :func:`sim.control.model.control_model`)."""
    return Controller(model, settings).run(qpos_ref, fps)
