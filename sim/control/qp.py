"""The whole-body QP: joint torques that track desired accelerations through floor contacts.

Whole-body inverse dynamics with contact-force optimisation (the standard task-space / QP
controller of legged robots and physics-based characters, e.g. de Lasa et al. 2010
"Feature-based locomotion controllers"; Wensing & Orin 2013). At every control update:

* desired accelerations of ALL ``nv`` dofs, root included:
  ``qacc_des = qacc_ref + Kp (q_ref ⊖ q) + Kd (qvel_ref - qvel)`` (``mj_differentiatePos``
  for the free joint), and for each foot a world-orientation task
  ``J_rot qacc ≈ Kp_f log(R_ref Rᵀ) + Kd_f (w_ref - w)`` so a foot lands flat;
* a QP over ``x = (qacc, lambda)`` with ``lambda >= 0`` the weights of the edges of a
  linearised friction pyramid at each floor contact (the sole corners within
  :attr:`ControlSettings.contact_margin` of the floor, so the whole sole is usable):

      min  |W (qacc - qacc_des)|² + w_f |J_rot qacc - a_f|² + w_c |J_c qacc + k_c J_c qvel|²
           + |W_com (J_com qacc - a_com)|² + w_lambda |lambda|²
      s.t. M_root qacc + c_root = (J_cᵀ E lambda)_root        (the 6 unactuated rows)

  so the root's acceleration can come from contact forces only; ``a_com = a_ref + Kp (c_ref -
  c) + Kd (v_ref - v)`` steers the whole-body centre of mass (``mj_jacSubtreeCom``; the
  reference's from ``subtree_com``, finite-differenced) — the centroidal (linear momentum)
  task of Wensing & Orin 2013, which only contact forces can satisfy;
* joint torques ``tau = (M qacc + c - J_cᵀ E lambda)_hinges`` go to the actuators (motors in
  the control model, :func:`sim.control.model.control_model`); MuJoCo then simulates the
  contacts itself.

Shapes: ``nq``/``nv``/``nu`` MuJoCo sizes, ``C`` floor contacts.
"""

from __future__ import annotations

from collections.abc import Iterator

import mujoco
import numpy as np
from qpsolvers import solve_qp

from avatarsim.sim.control.model import BodyIndices
from avatarsim.sim.control.settings import ROOT_DOF, ControlSettings
from avatarsim.sim.soles import corner_positions

QP_SOLVER = "daqp"


class WholeBodyQP:
    """The QP of the module docstring on the simulation ``data`` of the control ``model``."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        body: BodyIndices,
        settings: ControlSettings,
    ):
        self.model, self.data, self.body, self.settings = model, data, body, settings
        s, nv = settings, model.nv
        self.kp = np.full(nv, s.kp)
        self.kd = np.full(nv, s.kd)
        self.kp[:ROOT_DOF], self.kd[:ROOT_DOF] = s.kp_root, s.kd_root
        self.kp[:2] = s.kp_root_xy
        self.weight = np.ones(nv)
        self.weight[:ROOT_DOF] = s.root_weight
        mu = s.friction
        # Friction-pyramid edges on the floor, world axes (x, y, z) by edge.
        self.edges = np.array([[mu, 0, 1], [-mu, 0, 1], [0, mu, 1], [0, -mu, 1]], float).T
        self._ref_data = mujoco.MjData(model)  # the reference's kinematics for the foot tasks

    def torques(
        self,
        q_target: np.ndarray,
        v_target: np.ndarray,
        a_target: np.ndarray,
        com: np.ndarray,
        jac_com: np.ndarray,
        standing: np.ndarray,
    ) -> np.ndarray:
        """``(nu,)`` hinge torques towards ``q_target (nq,)``, ``v_target``, ``a_target
        (nv,)``, the reference centre of mass ``com (3, 3)`` (position, velocity,
        acceleration) with the simulated one's Jacobian ``jac_com (3, nv)``; feet
        ``standing (2,)`` are levelled (:meth:`foot_tasks`)."""
        m, d, s = self.model, self.data, self.settings
        nv = m.nv
        error = np.empty(nv)
        mujoco.mj_differentiatePos(m, error, 1.0, d.qpos, q_target)
        qacc_des = a_target + self.kp * error + self.kd * (v_target - d.qvel)
        mass = np.empty((nv, nv))
        mujoco.mj_fullM(m, d, mass)
        bias = d.qfrc_bias
        jc, je = self.contacts()
        nx = nv + je.shape[1]
        hess = np.zeros((nx, nx))
        grad = np.zeros(nx)
        hess[:nv, :nv] = np.diag(self.weight)
        grad[:nv] = -self.weight * qacc_des
        for jr, acc in self.foot_tasks(q_target, v_target, standing):
            hess[:nv, :nv] += s.foot_weight * jr.T @ jr
            grad[:nv] -= s.foot_weight * jr.T @ acc
        wcom = np.asarray(s.com_weight)[:, None]
        com_acc = (
            com[2] + s.kp_com * (com[0] - d.subtree_com[0]) + s.kd_com * (com[1] - jac_com @ d.qvel)
        )
        hess[:nv, :nv] += jac_com.T @ (wcom * jac_com)
        grad[:nv] -= jac_com.T @ (wcom[:, 0] * com_acc)
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
        return generalised[self.body.dof]

    def contacts(self) -> tuple[np.ndarray, np.ndarray]:
        """``(3C, nv)`` Jacobian of the candidate floor contacts and ``(nv, 4C)`` generalised
        forces of their friction-pyramid edges (world frame: the floor's normal is +Z).

        The candidates are the corners of the sole boxes that are within
        :attr:`ControlSettings.contact_margin` of the floor, not MuJoCo's reported contacts:
        on one foot MuJoCo often reports 1-3 points, which leaves the QP a support polygon
        too small to push the body sideways; the corners span the whole sole."""
        m, d, body = self.model, self.data, self.body
        corners = corner_positions(d, body.sole_geoms, body.sole_corners)
        in_contact = np.zeros(m.ngeom, bool)
        in_contact[d.contact.geom[: d.ncon].ravel()] = True  # MuJoCo's contacts
        touching = in_contact[body.sole_geoms]
        near = (corners[..., 2] < self.settings.contact_margin) & touching[:, None]  # (G, 8)
        geom, corner = np.nonzero(near)
        points = corners[geom, corner]
        jc = np.empty((3 * points.shape[0], m.nv))
        for n, (point, g) in enumerate(zip(points, body.sole_geoms[geom], strict=True)):
            mujoco.mj_jac(m, d, jc[3 * n : 3 * n + 3], None, point, m.geom_bodyid[g])
        je = np.einsum("cin,ie->nce", jc.reshape(-1, 3, m.nv), self.edges)
        return jc, je.reshape(m.nv, -1)

    def foot_tasks(
        self, q_target: np.ndarray, v_target: np.ndarray, standing: np.ndarray
    ) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Per foot: ``(3, nv)`` rotational Jacobian and the ``(3,)`` desired angular
        acceleration towards the reference foot's orientation, levelled (sole normal turned
        onto +Z by the smallest rotation) while the reference stands on it (``standing``):
        retargeted clips often stand on a tilted sole, which would leave one edge of the foot
        on the floor."""
        m, d, s, ref = self.model, self.data, self.settings, self._ref_data
        ref.qpos[:] = q_target
        mujoco.mj_kinematics(m, ref)
        mujoco.mj_comPos(m, ref)
        jr, jr_ref = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        conj, err_quat, err = np.empty(4), np.empty(4), np.empty(3)
        target, level = np.empty(4), np.empty(4)
        feet = zip(self.body.feet, self.body.sole_normal, standing, strict=True)
        for foot, normal, stand in feet:
            mujoco.mj_jacBody(m, d, None, jr, foot)
            mujoco.mj_jacBody(m, ref, None, jr_ref, foot)
            target[:] = ref.xquat[foot]
            if stand:
                mujoco.mju_quatZ2Vec(level, ref.xmat[foot].reshape(3, 3) @ normal)
                mujoco.mju_negQuat(level, level)
                mujoco.mju_mulQuat(target, level, ref.xquat[foot])
            mujoco.mju_negQuat(conj, d.xquat[foot])
            mujoco.mju_mulQuat(err_quat, target, conj)
            mujoco.mju_quat2Vel(err, err_quat, 1.0)
            yield jr.copy(), s.kp_foot * err + s.kd_foot * (jr_ref @ v_target - jr @ d.qvel)
