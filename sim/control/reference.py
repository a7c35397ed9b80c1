"""The reference motion as the controller plays it: prepared once (:meth:`Reference.build`),
read at its fractional clock (:meth:`Reference.at`, the one interpolation of the reference in
the package), and looped on its gait cycle (:func:`looped`).

Shapes: ``T`` reference frames, ``nq``/``nv`` MuJoCo sizes, 17 body17 sites.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.ndimage import gaussian_filter1d
from scipy.spatial.distance import cdist

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.sim.control.balance import swing_weights
from avatarsim.sim.control.model import BodyIndices
from avatarsim.sim.control.settings import ControlSettings


@dataclass(frozen=True)
class ReferencePoint:
    """The reference at one fractional frame (:meth:`Reference.at`).

    Attributes:
        frame: the frame played, within ``[0, T - 1]``.
        qpos: ``(nq,)`` configuration, interpolated on the manifold (``mj_integratePos``).
        qvel, qacc: ``(nv,)`` velocity and acceleration.
        swing: ``(2,)`` foot-placement weights (:func:`sim.control.balance.swing_weights`).
        com: ``(3, 3)`` whole-body centre of mass position, velocity, acceleration.

    The nearest frame's configuration (falls are judged on it) is
    :meth:`Reference.frame_qpos` of ``frame``, the body17 sites :meth:`Reference.sites_at`:
    only the search's cost reads them.
    """

    frame: float
    qpos: np.ndarray
    qvel: np.ndarray
    qacc: np.ndarray
    swing: np.ndarray
    com: np.ndarray


@dataclass(frozen=True)
class Reference:
    """A reference motion prepared for control (:meth:`build`).

    Attributes:
        model: the control model (:func:`sim.control.model.control_model`) it was built on.
        qpos: ``(T, nq)`` configurations at ``fps``.
        forward: ``(T, nv)`` velocity from each frame to the next (interpolation).
        qvel, qacc: ``(T, nv)`` smoothed velocities and accelerations.
        swing: ``(T, 2)`` foot-placement weights (:func:`sim.control.balance.swing_weights`).
        sites: ``(T, 17, 3)`` body17 site positions.
        com: ``(T, 3, 3)`` whole-body centre of mass position, velocity, acceleration.
        fps: frame rate.
    """

    model: mujoco.MjModel
    qpos: np.ndarray
    forward: np.ndarray
    qvel: np.ndarray
    qacc: np.ndarray
    swing: np.ndarray
    sites: np.ndarray
    com: np.ndarray
    fps: float

    @classmethod
    def build(
        cls,
        model: mujoco.MjModel,
        body: BodyIndices,
        qpos_ref: np.ndarray,
        fps: float,
        settings: ControlSettings,
    ) -> Reference:
        """Precompute what the controller needs of ``qpos_ref (T, nq)`` sampled at ``fps``."""
        qpos_ref = np.asarray(qpos_ref, dtype=float)
        if qpos_ref.ndim != 2 or qpos_ref.shape[1] != model.nq or not np.isfinite(qpos_ref).all():
            raise MotionValueError(
                f"reference must be finite (T, {model.nq}), got {qpos_ref.shape}"
            )
        if qpos_ref.shape[0] < 2:
            raise MotionValueError("reference must have at least 2 frames")
        qvel = reference_velocities(model, qpos_ref, fps)
        sigma = settings.smoothing_frames
        if sigma > 0:
            qvel = gaussian_filter1d(qvel, sigma, axis=0, mode="nearest")
        qacc = np.gradient(qvel, 1.0 / fps, axis=0)
        if sigma > 0:
            qacc = gaussian_filter1d(qacc, sigma, axis=0, mode="nearest")
        ankle_heights = site_positions(model, qpos_ref, body.ankles)[..., 2]
        return cls(
            model=model,
            qpos=qpos_ref,
            forward=forward_differences(model, qpos_ref, fps),
            qvel=qvel,
            qacc=qacc,
            swing=swing_weights(ankle_heights, fps, settings),
            sites=site_positions(model, qpos_ref, body.sites),
            com=with_derivatives(centre_of_mass(model, qpos_ref), fps),
            fps=fps,
        )

    @property
    def n_frames(self) -> int:
        return self.qpos.shape[0]

    def at(self, clock: float) -> ReferencePoint:
        """The reference at fractional frame ``clock`` (held at its last frame past the end):
        linear between frames, on the manifold for the configuration."""
        frame, i, a = self._interpolation(clock)
        qpos = self.qpos[i].copy()
        mujoco.mj_integratePos(self.model, qpos, self.forward[i], a / self.fps)
        return ReferencePoint(
            frame=frame,
            qpos=qpos,
            qvel=_blend(self.qvel, i, a),
            qacc=_blend(self.qacc, i, a),
            swing=_blend(self.swing, i, a),
            com=_blend(self.com, i, a),
        )

    def sites_at(self, clocks: np.ndarray | float) -> np.ndarray:
        """``(..., 17, 3)`` body17 sites at the fractional frames ``clocks (...)``,
        interpolated as :meth:`at`."""
        _, i, a = self._interpolation(clocks)
        return _blend(self.sites, i, a)

    def frame_qpos(self, clocks: np.ndarray | float) -> np.ndarray:
        """``(..., nq)`` configuration of the frame nearest to each of ``clocks (...)``."""
        return self.qpos[np.round(clocks).astype(int)]

    def _interpolation(self, clocks):
        """Clamped ``clocks``, the frame ``i`` before each and the weight ``a`` of the next."""
        n = self.n_frames
        frame = np.minimum(clocks, n - 1.0)
        i = np.minimum(frame.astype(int), n - 2)
        return frame, i, frame - i


def _blend(values: np.ndarray, i: np.ndarray | int, a: np.ndarray | float) -> np.ndarray:
    """``(1 - a) values[i] + a values[i + 1]``, ``a`` broadcast over the trailing axes."""
    if isinstance(a, np.ndarray) and a.ndim:  # a scalar (one clock) broadcasts as it is
        a = a.reshape(a.shape + (1,) * (values.ndim - 1))
    return (1 - a) * values[i] + a * values[i + 1]


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


def with_derivatives(x: np.ndarray, fps: float) -> np.ndarray:
    """``(T, 3, ...)`` ``x (T, ...)``, its velocity and acceleration (central differences,
    each smoothed by a 1-frame Gaussian: finite differences of mocap are noisy)."""
    vel = gaussian_filter1d(np.gradient(x, 1.0 / fps, axis=0), 1.0, axis=0)
    acc = gaussian_filter1d(np.gradient(vel, 1.0 / fps, axis=0), 1.0, axis=0)
    return np.stack([x, vel, acc], axis=1)


def centre_of_mass(model: mujoco.MjModel, qpos: np.ndarray) -> np.ndarray:
    """``(T, 3)`` whole-body centre of mass of ``qpos (T, nq)``."""
    data = mujoco.MjData(model)
    out = np.empty((qpos.shape[0], 3))
    for t in range(qpos.shape[0]):  # MuJoCo evaluates one state per call
        data.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        out[t] = data.subtree_com[0]
    return out


def site_positions(model: mujoco.MjModel, qpos: np.ndarray, sites: np.ndarray) -> np.ndarray:
    """``(T, S, 3)`` positions of the sites ``sites (S,)`` for ``qpos (T, nq)`` (kinematics
    only)."""
    data = mujoco.MjData(model)
    out = np.empty((qpos.shape[0], sites.size, 3))
    for t in range(qpos.shape[0]):  # MuJoCo evaluates one state per call
        data.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, data)
        out[t] = data.site_xpos[sites]
    return out


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
    turn_angle = float(quat.yaw(qpos[j, 3:7]) - quat.yaw(qpos[i, 3:7]))
    rot = np.array(
        [[np.cos(turn_angle), -np.sin(turn_angle)], [np.sin(turn_angle), np.cos(turn_angle)]]
    )
    turn = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), turn_angle)
    pieces = [qpos[:j]]
    repeat = qpos[i:j].copy()
    for _ in range(int(np.ceil((need - j) / (j - i)))):
        repeat = repeat.copy()
        repeat[:, :2] = (repeat[:, :2] - qpos[i, :2]) @ rot.T + qpos[j, :2]
        repeat[:, 3:7] = quat.mul(turn, repeat[:, 3:7])
        pieces.append(repeat)
    return np.vstack(pieces)[:need]
