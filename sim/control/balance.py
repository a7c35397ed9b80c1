"""Balance: where a swinging foot lands and how fast the reference is played.

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
robust gaits").

Shapes: ``T`` reference frames, ``nq``/``nv`` MuJoCo sizes.
"""

from __future__ import annotations

import mujoco
import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.sim.control.model import BodyIndices
from avatarsim.sim.control.settings import GRAVITY, ControlSettings


def reference_stance(ankle_heights: np.ndarray, stance_height: float) -> np.ndarray:
    """``(T, 2)`` whether each reference foot (left, right) stands: its ankle within
    ``stance_height`` (m) of its lowest height in the clip. ``ankle_heights (T, 2)`` (m).
    The controller's only stance labelling."""
    return ankle_heights < ankle_heights.min(axis=0) + stance_height


def swing_weights(ankle_heights: np.ndarray, fps: float, settings: ControlSettings) -> np.ndarray:
    """``(T, 2)`` 0..1 weight of the foot-placement shift per leg (left, right) of a reference
    whose ankles are ``ankle_heights (T, 2)`` high at ``fps``: 0 while the reference foot
    stands (:func:`reference_stance`), ramping to 1 over ``swing_ramp_s`` after lift-off."""
    swing = ~reference_stance(ankle_heights, settings.stance_height)
    since = np.zeros(swing.shape)
    for t in range(1, swing.shape[0]):  # a running count: sequential by definition
        since[t] = np.where(swing[t], since[t - 1] + 1.0 / fps, 0.0)
    ramp = max(settings.swing_ramp_s, 1e-9)
    return np.where(swing, np.clip(since / ramp, 1.0 / (ramp * fps), 1.0), 0.0)


def heading_frame(qpos: np.ndarray) -> np.ndarray:
    """``(2, 2)`` rotation taking world horizontal vectors to (forward, left) of the root's
    heading in configuration ``qpos (nq,)``."""
    yaw = quat.yaw(qpos[3:7])
    return np.array([[np.cos(yaw), np.sin(yaw)], [-np.sin(yaw), np.cos(yaw)]])


def capture_error(
    data: mujoco.MjData, jac_com: np.ndarray, qpos_ref: np.ndarray, com_ref: np.ndarray
) -> np.ndarray:
    """``(2,)`` horizontal capture-point error, simulated (``data``, its centre-of-mass
    Jacobian ``jac_com (3, nv)``) minus reference, along the heading of ``qpos_ref (nq,)`` and
    to its left (m). ``com_ref (3, 3)``: reference centre of mass position, velocity,
    acceleration."""
    omega = np.sqrt(GRAVITY / com_ref[0][2])
    capture = data.subtree_com[0, :2] + (jac_com @ data.qvel)[:2] / omega
    return heading_frame(qpos_ref) @ (capture - com_ref[0][:2] - com_ref[1][:2] / omega)


def clock_rate(error: np.ndarray, settings: ControlSettings) -> float:
    """The reference clock's rate (frames per frame) for the capture-point ``error (2,)``
    (:func:`capture_error`): ``1 + clock_gain x`` its forward part, bounded."""
    bound = settings.max_clock_change
    return 1.0 + np.clip(settings.clock_gain * error[0], -bound, bound)


def step_shift(qpos_ref: np.ndarray, error: np.ndarray, settings: ControlSettings) -> np.ndarray:
    """``(2,)`` world shift of a swinging foot's target: the capture-point ``error (2,)``
    (:func:`capture_error`, in the heading frame of ``qpos_ref (nq,)``) times
    :attr:`ControlSettings.capture_gain`, bounded by ``max_step_shift``."""
    shift = heading_frame(qpos_ref).T @ (np.asarray(settings.capture_gain) * error)
    norm = np.linalg.norm(shift)
    if norm > settings.max_step_shift:
        shift *= settings.max_step_shift / norm
    return shift


def place_feet(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    body: BodyIndices,
    q_target: np.ndarray,
    shift: np.ndarray,
    swing: np.ndarray,
) -> None:
    """Shift the swinging hips' targets in ``q_target (nq,)`` (in place) so that the ankles
    move by ``swing (2,) x shift (2,)`` (world, horizontal): ``J_hip⁺ shift`` with the
    ankle's horizontal Jacobian over the hip hinges (damped pseudo-inverse)."""
    jac = np.zeros((3, model.nv))
    for side in np.flatnonzero(swing > 0):
        mujoco.mj_jacSite(model, data, jac, None, body.ankles[side])
        j = jac[:2, body.hip_dof[side]]
        dq = j.T @ np.linalg.solve(j @ j.T + 1e-4 * np.eye(2), shift)
        q_target[body.hip_qadr[side]] += swing[side] * dq
