"""Inverse kinematics on the humanoid with mink: frames (sites or bodies) to target positions.

Shapes: ``T`` frames, ``K`` targets, ``nq`` MuJoCo position coordinates. One
:class:`HumanoidIK` holds a model, the names of the frames it steers (the body17 sites of
:meth:`BodyDescription.to_mjcf`, or any named body), per-target position and orientation
costs, and a posture target (the rest pose unless given). Per frame it runs mink's
differential IK (a QP over the joint velocities, solved by daqp) to convergence:

    min  sum_k  w_k |p_k(q) - p*_k|^2 + o_k |log(R_k(q)^T R*_k)|^2 + c |q - q_rest|^2
    s.t. q within the model's joint ranges (``mink.ConfigurationLimit``)

with Levenberg-Marquardt damping on the frame tasks, so unreachable targets pull the limb
straight at them instead of making the step explode, and a small damping ``d |dq|^2`` of
every step (:attr:`IKSettings.damping`), without which the iteration does not converge and
its output depends on BLAS rounding. The posture term excludes the free root. A
trajectory is solved frame after frame, each warm-started from the previous solution
(so consecutive solutions stay on one branch); the first frame starts from the posture
with its root rigidly fitted to the targets (Kabsch), so a target set facing -X does not
begin half a turn away.

Both ``sim`` (retargeting) and ``synthesis`` (the head + hands baseline) use this module.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mink
import mujoco
import numpy as np
from scipy.spatial.transform import Rotation
from threadpoolctl import threadpool_limits

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body.description import BodyDescription
from avatarsim.avatar_models.body.errors import BodyError
from avatarsim.avatar_models.motion import Motion

SOLVER = "daqp"
ROOT_NQ = 7
"""Free-joint coordinates at the front of qpos: position (3) and wxyz quaternion (4)."""


@dataclass(frozen=True)
class IKSettings:
    """Costs and convergence of :class:`HumanoidIK` (costs are relative weights).

    Attributes:
        posture_cost: weight of ``|q - q_posture|^2`` per hinge (radians), small so targets win.
        lm_damping: Levenberg-Marquardt damping of the frame tasks.
        damping: ``d |dq|^2`` added to every QP step, on every coordinate (the free root's
            too). It damps the step, not the solution (a converged ``q`` has ``dq = 0``).
            Why it is needed: the posture term is the only curvature of directions that
            move no steered frame (the pelvis hinges sit at the root's origin and duplicate
            its rotation; spine and clavicle chains, forearm twist), ``posture_cost^2 =
            1e-6``, against ``~170`` for the IK baseline's head target: the QP Hessian's
            condition number was ~5e8 and the full Gauss-Newton step went 0.5-1 rad along
            those directions, past where the linearisation holds, so the iteration
            oscillated (13 joint limits switching, never within the tolerance) instead of
            converging. Such a map amplifies any difference ~3x per frame: BLAS rounding of
            ``J^T W J`` (another OpenBLAS kernel sums in another order) gave 7e-9 rad after
            the first frame and 1 rad 20 frames later: 41 cm of body17 position and 1.8 ->
            2.5 cm of the IK baseline's mean hand error (OpenBLAS Haswell vs Sandybridge
            kernels, builtin box, seed 2). ``d = 1e-4`` stopped that on reachable targets
            but not on unreachable ones (a 1.95 m subject's targets on the 1.8 m avatar:
            1e-12 m of target noise still became 0.79 m); ``d = 1e-2`` (1e4 x the posture
            curvature, 1/100 of a unit position cost's) contracts there too (3e-12 m, mean
            residual 12.4 -> 3.7 cm), and the IK baseline then agrees across the two
            kernels to 1e-6 cm with hand errors of 0.006 cm instead of 0.02-3.6 cm.
        max_iterations: QP steps per frame at most (the first frame gets ``4x`` as many).
        tolerance: stop a frame once a step moves no coordinate by more than this.
    """

    posture_cost: float = 1e-3
    lm_damping: float = 1e-3
    max_iterations: int = 20
    tolerance: float = 1e-4
    damping: float = 1e-2


@dataclass(frozen=True)
class IKResult:
    """A solved trajectory.

    Attributes:
        qpos: ``(T, nq)`` joint configurations, within the model's joint ranges.
        residual: ``(T, K)`` distance (metres) from each steered frame to its target.
        iterations: ``(T,)`` QP steps taken per frame.
    """

    qpos: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray

    @property
    def residual_cm(self) -> np.ndarray:
        """``(T,)`` mean target distance per frame in centimetres."""
        return 100.0 * self.residual.mean(axis=1)


def humanoid_model(body: BodyDescription) -> mujoco.MjModel:
    """The compiled MuJoCo model of ``body`` (:attr:`BodyDescription.model`, compiled once
    per body and shared: read it, do not edit it)."""
    return body.model


class HumanoidIK:
    """Position (and optional orientation) IK for named frames of a free-root humanoid.

    Args:
        model: a MuJoCo model with a free root joint first (e.g. :func:`humanoid_model`).
        frames: names of the steered sites (``frame_type="site"``) or bodies (``"body"``).
        position_cost: one weight, or one per frame.
        orientation_cost: one weight, or one per frame; frames with a positive weight need
            target orientations.
        posture: ``(nq,)`` configuration the hinges are pulled towards (default: ``qpos0``,
            the rest pose).
        settings: costs and convergence.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        frames: Sequence[str],
        frame_type: str = "site",
        position_cost: float | Sequence[float] = 1.0,
        orientation_cost: float | Sequence[float] = 0.0,
        posture: np.ndarray | None = None,
        settings: IKSettings | None = None,
    ):
        if model.njnt == 0 or model.jnt_type[0] != mujoco.mjtJoint.mjJNT_FREE:
            raise BodyError("humanoid IK needs a model whose first joint is the free root")
        obj = {"site": mujoco.mjtObj.mjOBJ_SITE, "body": mujoco.mjtObj.mjOBJ_BODY}.get(frame_type)
        if obj is None:
            raise BodyError(f"frame_type must be 'site' or 'body', got {frame_type!r}")
        unknown = [f for f in frames if mujoco.mj_name2id(model, obj, f) < 0]
        if unknown or not frames:
            raise BodyError(f"the model has no {frame_type}s named {unknown or 'at all'}")
        self.model = model
        self.frames = tuple(frames)
        self.frame_type = frame_type
        self.settings = settings or IKSettings()
        k = len(self.frames)
        pos_w = np.broadcast_to(np.asarray(position_cost, dtype=float), (k,))
        self.orientation_cost = np.broadcast_to(np.asarray(orientation_cost, dtype=float), (k,))
        self.posture = model.qpos0.copy() if posture is None else np.asarray(posture, float)
        self.configuration = mink.Configuration(model)
        self.tasks = [
            mink.FrameTask(f, frame_type, w, o, lm_damping=self.settings.lm_damping)
            for f, w, o in zip(self.frames, pos_w, self.orientation_cost, strict=True)
        ]
        posture_task = mink.PostureTask(model, cost=self.settings.posture_cost)
        posture_task.set_target(self.posture)
        self.posture_task = posture_task
        self.limits = [mink.ConfigurationLimit(model, gain=0.95)]
        self._ids = np.array([mujoco.mj_name2id(model, obj, f) for f in self.frames])
        # Per-coordinate bounds: hinge ranges; the root's 7 numbers are unbounded.
        hinge = (model.jnt_type == mujoco.mjtJoint.mjJNT_HINGE) & model.jnt_limited.astype(bool)
        self.qpos_lower = np.full(model.nq, -np.inf)
        self.qpos_upper = np.full(model.nq, np.inf)
        self.qpos_lower[model.jnt_qposadr[hinge]] = model.jnt_range[hinge, 0]
        self.qpos_upper[model.jnt_qposadr[hinge]] = model.jnt_range[hinge, 1]

    # -- frame positions -------------------------------------------------------------------
    def frame_positions(self, qpos: np.ndarray) -> np.ndarray:
        """``(K, 3)`` world positions of the steered frames at ``qpos (nq,)``."""
        self.configuration.update(qpos)
        return self._current_positions()

    def _current_positions(self) -> np.ndarray:
        data = self.configuration.data
        xpos = data.site_xpos if self.frame_type == "site" else data.xpos
        return xpos[self._ids].copy()

    def fitted_root(self, positions: np.ndarray) -> np.ndarray:
        """``(nq,)`` the posture with its root moved by the rigid transform (Kabsch) that best
        maps the posture's frame positions onto ``positions (K, 3)`` (NaN rows ignored)."""
        q = self.posture.copy()
        q[:3], q[3:7] = 0.0, (1.0, 0.0, 0.0, 0.0)
        rest = self.frame_positions(q)
        ok = np.isfinite(positions).all(axis=1)
        if ok.sum() < 3:  # a rigid fit needs three points; translate only
            q[:3] = (positions[ok] - rest[ok]).mean(axis=0) if ok.any() else self.posture[:3]
            return q
        src, dst = rest[ok], positions[ok]
        rot, _ = Rotation.align_vectors(dst - dst.mean(0), src - src.mean(0))
        q[3:7] = quat.from_scipy(rot)
        q[:3] = dst.mean(0) - rot.apply(src.mean(0))
        return q

    # -- solving ----------------------------------------------------------------------------
    def solve_frame(
        self,
        positions: np.ndarray,
        q_init: np.ndarray,
        orientations: np.ndarray | None = None,
        max_iterations: int | None = None,
    ) -> tuple[np.ndarray, np.ndarray, int]:
        """One frame: ``positions (K, 3)`` (NaN rows are dropped), optional wxyz
        ``orientations (K, 4)``, start ``q_init (nq,)``. Returns ``(qpos (nq,),
        residual (K,) metres, iterations)``; residuals of dropped targets are NaN."""
        positions = np.asarray(positions, dtype=float)
        ok = np.isfinite(positions).all(axis=1)
        active = []
        for k, task in enumerate(self.tasks):
            if not ok[k]:
                continue
            wxyz = (1.0, 0.0, 0.0, 0.0)
            if self.orientation_cost[k] > 0:
                if orientations is None or not np.isfinite(orientations[k]).all():
                    raise BodyError(
                        f"frame {self.frames[k]!r} has an orientation cost but no "
                        "target orientation"
                    )
                wxyz = orientations[k]
            task.set_target(mink.SE3(np.concatenate([wxyz, positions[k]])))
            active.append(task)
        tasks = [*active, self.posture_task]
        q = np.clip(q_init, self.qpos_lower, self.qpos_upper)
        self.configuration.update(q)
        steps = max_iterations or self.settings.max_iterations
        it = 0
        for it in range(1, steps + 1):  # noqa: B007 - the count is returned
            dq = mink.solve_ik(
                self.configuration,
                tasks,
                1.0,
                SOLVER,
                damping=self.settings.damping,
                limits=self.limits,
            )
            self.configuration.integrate_inplace(dq, 1.0)
            if np.abs(dq).max() < self.settings.tolerance:
                break
        residual = np.linalg.norm(self._current_positions() - positions, axis=1)
        return self.configuration.q.copy(), residual, it

    def solve(
        self,
        positions: np.ndarray,
        orientations: np.ndarray | None = None,
        q_init: np.ndarray | None = None,
    ) -> IKResult:
        """Solve ``positions (T, K, 3)`` (and wxyz ``orientations (T, K, 4)``) frame by frame,
        warm-started; ``q_init (nq,)`` defaults to :meth:`fitted_root` on the first frame.

        Frames are solved in order on purpose: each starts from the previous solution."""
        positions = np.asarray(positions, dtype=float)
        if positions.ndim != 3 or positions.shape[1:] != (len(self.frames), 3):
            raise BodyError(f"targets must be (T, {len(self.frames)}, 3), got {positions.shape}")
        n = positions.shape[0]
        qpos = np.empty((n, self.model.nq))
        residual = np.empty((n, len(self.frames)))
        iterations = np.empty(n, dtype=np.int64)
        q = self.fitted_root(positions[0]) if q_init is None else np.asarray(q_init, float)
        first_steps = 4 * self.settings.max_iterations
        # The QPs are ~100 x 66: BLAS threads cost more than they save (10x on a busy box).
        with threadpool_limits(1, user_api="blas"):
            for t in range(n):
                orient = None if orientations is None else orientations[t]
                q, residual[t], iterations[t] = self.solve_frame(
                    positions[t], q, orient, first_steps if t == 0 else None
                )
                qpos[t] = q
        return IKResult(qpos, residual, iterations)


def motion_from_qpos(body: BodyDescription, qpos: np.ndarray, fps: float) -> Motion:
    """The ``Motion`` on ``body.skeleton`` whose qpos is ``qpos (T, nq)`` (the inverse of
    :meth:`BodyDescription.qpos_from_motion`); fixed joints keep their rest rotation."""
    qpos = np.asarray(qpos, dtype=float)
    n_hinge_joints = len(body.body_order) - 1
    if qpos.ndim != 2 or qpos.shape[1] != ROOT_NQ + 3 * n_hinge_joints:
        raise BodyError(f"qpos must be (T, {ROOT_NQ + 3 * n_hinge_joints}), got {qpos.shape}")
    n = qpos.shape[0]
    local = np.zeros((n, body.skeleton.n_joints, 4))
    local[..., 0] = 1.0
    local[:, 0] = qpos[:, 3:7]
    # Every hinged joint at once (scipy per joint cost ~20 ms a frame, the most of a step).
    joints = list(body.body_order[1:])
    angles = qpos[:, ROOT_NQ:].reshape(n, len(joints), 3)
    axes = quat.euler_axes([body.hinge_order(j) for j in joints])
    local[:, joints] = quat.normalize(quat.from_euler(angles, axes))
    return Motion(body.skeleton, fps, qpos[:, :3], local)
