"""AvatarGo's full-body IK as damped least squares: the QP's costs without the QP.

§3.4 drives the avatar with Unity's IK (closed-form limb solvers and a few iterations of a
full-body solver each frame); this repository stands in with mink on the humanoid
(:class:`~avatar_models.body.ik.HumanoidIK`: one QP per iteration, joint ranges as
inequality constraints). Built per tick, that QP costs ~1.6 ms per iteration on one core
(mink's task bookkeeping and the dense QP), over our 1 ms aim for a whole tick.

:class:`LeastSquaresIK` minimises the same objective (the same frame tasks, costs, posture
term, Levenberg-Marquardt and step damping, :class:`~avatar_models.body.ik.IKSettings`) in
closed form: with world-frame site Jacobians ``J_k`` (MuJoCo's ``mj_jacSite``), errors
``e_k = (p*_k - p_k, log(R*_k R_k^T))`` weighted by ``W_k`` (position, orientation cost)::

    (sum_k J_k^T W_k^2 J_k + c^2 P + lambda I) dq = sum_k J_k^T W_k^2 e_k + c^2 P (q0 - q)

with ``P`` the hinges' selector, ``c`` the posture cost and ``lambda = d + l sum_k |W_k
e_k|^2`` (damping ``d``, LM damping ``l``): one 72 x 72 Cholesky solve. The joint ranges
are kept by an active set instead of constraints: hinges the step would take out of range
are held at their bound and the others re-solved (a few passes). mink's frame error is the
body-frame SE(3) twist ``log(T_b^-1 T_t)``, whose translation couples in the rotation
error; ours is the world-frame pair, equal at the solution and to first order near it.

Measured (``study_run``, 2 s, realistic noise, 2 iterations a tick, exact offsets, cm):
as mink on the generator's wave (head/feet/root 0.1-0.4 either way) and box (1.7-3.4
against 0.6-3.7), worse while walking (feet 5.6/6.8, root 6.0 against 2.5/2.7, 2.2): with
goals that conflict (fast swing feet, the fixed baseline's) it settles elsewhere than the
QP. Hence not mink's replacement (:data:`~synthesis.avatargo.synthesizer.QP_SOLVERS`).
"""

from __future__ import annotations

import mujoco
import numpy as np
from scipy.linalg import cho_factor, cho_solve

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body.errors import BodyError
from avatarsim.avatar_models.body.ik import ROOT_NQ, HumanoidIK

ROOT_NV = 6
ACTIVE_SET_PASSES = 4
"""Free-root velocities at the front of qvel (no posture pull on them)."""


def rotation_log(r: np.ndarray) -> np.ndarray:
    """``(K, 3)`` rotation vectors of rotation matrices ``r (K, 3, 3)`` (angle < pi)."""
    skew = np.stack([r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]], 1)
    sin2 = np.linalg.norm(skew, axis=1)  # 2 sin(angle)
    cos = 0.5 * (np.trace(r, axis1=1, axis2=2) - 1.0)
    angle = np.arctan2(0.5 * sin2, cos)
    scale = np.where(sin2 > 1e-12, angle / np.maximum(sin2, 1e-12), 0.5)
    return skew * scale[:, None]


class LeastSquaresIK(HumanoidIK):
    """:class:`~avatar_models.body.ik.HumanoidIK` (same arguments, root fit and frame
    positions) whose :meth:`solve_frame` takes damped least-squares steps (module
    docstring). Steers sites only."""

    def __init__(self, model: mujoco.MjModel, frames, **kwargs):
        super().__init__(model, frames, "site", **kwargs)
        k, nv = len(self.frames), model.nv
        self.site_ids = np.array(
            [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f) for f in self.frames]
        )
        pos_w = np.broadcast_to(np.asarray(kwargs.get("position_cost", 1.0), float), (k,))
        self._weights = np.concatenate([pos_w[:, None], self.orientation_cost[:, None]], 1)
        self._jac = np.zeros((k, 2, 3, nv))
        self._posture = np.full(nv, self.settings.posture_cost**2)
        self._posture[:ROOT_NV] = 0.0
        if model.nq != nv + 1 or model.njnt != nv - ROOT_NV + 1:
            raise BodyError("least-squares IK needs a free root and hinges only")
        self._lower, self._upper = self.qpos_lower[ROOT_NQ:], self.qpos_upper[ROOT_NQ:]

    def _step(self, positions: np.ndarray, orientations: np.ndarray, ok: np.ndarray) -> float:
        """One damped least-squares step from the configuration's ``q``; returns the step's
        largest coordinate."""
        model, data = self.model, self.configuration.data
        for k in np.flatnonzero(ok):
            mujoco.mj_jacSite(model, data, self._jac[k, 0], self._jac[k, 1], self.site_ids[k])
        err = np.empty((len(self.frames), 2, 3))
        err[:, 0] = positions - data.site_xpos[self.site_ids]
        current = data.site_xmat[self.site_ids].reshape(-1, 3, 3)
        err[:, 1] = rotation_log(orientations @ current.transpose(0, 2, 1))
        w = self._weights[ok]
        a = (w[:, :, None, None] * self._jac[ok]).reshape(-1, model.nv)  # (6K, nv)
        e = (w[:, :, None] * err[ok]).reshape(-1)
        s = self.settings
        toward = np.empty(model.nv)
        mujoco.mj_differentiatePos(model, toward, 1.0, data.qpos, self.posture)
        hessian = a.T @ a
        hessian[np.diag_indices_from(hessian)] += self._posture + s.damping + s.lm_damping * (e @ e)
        gradient = a.T @ e + self._posture * toward
        dq = cho_solve(cho_factor(hessian, check_finite=False), gradient, check_finite=False)
        # Hinges the step would take out of range stay at their bound, the rest re-solved,
        # until none leaves its range (an active set that only grows: a few passes).
        hinge = data.qpos[ROOT_NQ:]
        held = np.zeros(hinge.size, bool)
        for _ in range(ACTIVE_SET_PASSES):
            stepped = hinge + dq[ROOT_NV:]
            out = (stepped < self._lower) | (stepped > self._upper)
            if not out.any():
                break
            held |= out
            h = np.flatnonzero(held)
            dq[h + ROOT_NV] = np.clip(stepped[h], self._lower[h], self._upper[h]) - hinge[h]
            free = np.concatenate([np.arange(ROOT_NV), np.flatnonzero(~held) + ROOT_NV])
            rhs = gradient[free] - hessian[np.ix_(free, h + ROOT_NV)] @ dq[h + ROOT_NV]
            dq[free] = cho_solve(
                cho_factor(hessian[np.ix_(free, free)], check_finite=False), rhs, check_finite=False
            )
        q = data.qpos.copy()
        mujoco.mj_integratePos(model, q, dq, 1.0)
        self.configuration.update(np.clip(q, self.qpos_lower, self.qpos_upper))
        return float(np.abs(dq).max())

    def solve_frame(
        self,
        positions: np.ndarray,
        q_init: np.ndarray,
        orientations: np.ndarray | None = None,
        max_iterations: int | None = None,
    ) -> tuple[np.ndarray, np.ndarray, int]:
        """As :meth:`HumanoidIK.solve_frame`, with ``orientations (K, 4)`` wxyz given for
        every frame (those of zero orientation cost are ignored)."""
        positions = np.asarray(positions, dtype=float)
        ok = np.isfinite(positions).all(axis=1)
        rot = quat.unit_to_matrix(quat.normalize(np.asarray(orientations, float)))
        self.configuration.update(np.clip(q_init, self.qpos_lower, self.qpos_upper))
        steps = max_iterations or self.settings.max_iterations
        it = 0
        for it in range(1, steps + 1):  # noqa: B007 - the count is returned
            if self._step(np.where(ok[:, None], positions, 0.0), rot, ok) < self.settings.tolerance:
                break
        residual = np.linalg.norm(
            self.configuration.data.site_xpos[self.site_ids] - positions, axis=1
        )
        return self.configuration.q.copy(), residual, it
