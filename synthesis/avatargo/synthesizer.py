"""``AvatarGo``: the self-avatar of AvatarGo (shared/papers/avatargo.txt §3) as a Synthesizer.

Construction is the Walk-In-Avatar step (§3.2-3.3) on one T-pose sample of the six devices
(:class:`~synthesis.base.TrackingFrame`):

1. roles and eye height from the plane through the devices
   (:func:`~synthesis.avatargo.calibration.identify_roles`);
2. the avatar scaled uniformly so that its head is as high as the user's under the
   headset (the eye height less the headset's mount, :func:`head_under`), stood in its
   T-pose where the user stands, facing where the user faces, its head where the user's
   is (the user "walks into" it; in simulation we place the avatar on the user instead);
3. the offsets of the joints in their devices' frames at t = 0: exact ones for the root,
   feet and head (eqs. 2-3, :func:`~synthesis.avatargo.offsets.exact_offsets`; §3.3 names
   root and feet and takes the head's rotation from the headset, we give the head's
   position the same exact offset so that the headset's fit cancels too) or, for the
   ``fixed`` baseline, the nominal constant ones for the root and feet
   (:func:`~synthesis.avatargo.offsets.fixed_offsets`); the wrists at the exact
   palm-to-wrist offset under the controllers (:mod:`synthesis.avatargo.hands`); and
   ``w0`` (eq. 1) for the spine.

Each tick (§3.4), by the per-tick IK ``solver`` (:data:`SOLVERS`):

- ``"analytic"`` (default): closed-form two-bone IK in place of the paper's Unity IK, on its
  effectors, no optimisation
  (:class:`~synthesis.avatargo.analytic_ik.AnalyticIK`, goals by :meth:`AvatarGo.
  analytic_goals`): the pelvis placed at its goal from the back tracker (eqs. 2-3), "the
  spine joint" turned by eq. 4's ``alpha_t`` (:func:`~synthesis.avatargo.spine.
  spine_bend_in_root`), the head turned as the headset, and closed-form two-bone limbs
  (:mod:`synthesis.two_bone`) onto the ankles' goals (eqs. 2-3) and the wrists' under the
  controllers, the ankles and wrists at their goal rotations. Vectorised over a batch's
  frames. Per tick on the shared 2-core machine (load average 3.6-4.8), CPU time:
  ``avatarsim bench avatargo`` (three runs, each after one of the previous version) p50
  0.85-1.01 ms (before 1.29-1.41), p99 1.48-1.86 ms (before 1.85-2.09), but mink's, whose
  tick barely changed, moved as much (p50 1.85-2.48 against 2.85-3.19): the machine's
  drift; per frame the best of 5 passes (``tests/measurements/avatargo_step_cost.py timing
  5``, four alternations) p50 0.63-0.66 ms against 0.70-1.09. With no other job (load
  0.5, three runs, after quat's cheaper ``mul``/``cross``): p50 0.51-0.53 ms, p99
  0.58-0.68 ms wall and CPU, under the 1 ms aim. Feet
  and root on their goals: built-in study (30 users, realistic noise) 0.67 / 0.62 cm mean,
  against mink's 1.4-1.7 / 2.2 cm; the head by forward kinematics 0.63 cm (mink 0.68).
- ``"mink"`` or ``"least-squares"`` (:data:`QP_SOLVERS`): full-body IK on the avatar's
  humanoid standing in for Unity's IK (:class:`~avatar_models.body.ik.HumanoidIK`,
  warm-started, a few iterations a tick) on goals for the root (pelvis), ankles and head
  from the offsets, the spine's bend (eq. 4) as the neck's soft goal and the wrists from
  the controllers (after the first tick at the controller less the palm offset turned by
  the wrist's solved rotation, see :data:`ORIENTATION_COST`). The QP bends the back and
  shoulders to bring a short arm's hand to its controller (built-in study: palm 0.84 cm,
  out of reach 3 % of frames), where the analytic limbs leave it short and report it
  (1.15 cm, 31 %); on CMU 09_01 it drags the left shoulder 31.5 cm off to do so.

Then finger IK on the controller handles (:mod:`synthesis.avatargo.fingers`) when the
avatar has the avatar rig's finger bones. Where a controller is out of the arm's reach
(:func:`~synthesis.avatargo.hands.out_of_reach`), the virtual controller is drawn in the
hand (reported per frame by :attr:`AvatarGo.attached`, with :attr:`AvatarGo.palm_distance`).

Untracked samples hold the device's last pose; until every device has been tracked once,
the avatar stands in its calibration T-pose.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import mujoco
import numpy as np
from threadpoolctl import threadpool_limits

from avatarsim.avatar_models import Motion, Skeleton, quat
from avatarsim.avatar_models.body import BodyDescription, build_body
from avatarsim.avatar_models.body.ik import HumanoidIK, IKSettings, motion_from_qpos
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams import TrackingStream
from avatarsim.render_cams.vr import FULL_BODY, Attachment, nominal_attachment
from avatarsim.synthesis.avatargo.analytic_ik import LEGS, AnalyticGoals, AnalyticIK
from avatarsim.synthesis.avatargo.calibration import Roles, classes_of, identify_roles
from avatarsim.synthesis.avatargo.fingers import FingerIK
from avatarsim.synthesis.avatargo.hands import (
    Grip,
    beyond_reach,
    grip_of,
    has_fingers,
    out_of_reach,
    palm_distance,
    palm_offsets,
)
from avatarsim.synthesis.avatargo.least_squares_ik import LeastSquaresIK
from avatarsim.synthesis.avatargo.offsets import TrackerOffsets, exact_offsets, fixed_offsets
from avatarsim.synthesis.avatargo.spine import spine_bend, spine_bend_in_root
from avatarsim.synthesis.base import (
    DEFAULT_RATE_HZ,
    FrameBatch,
    Poses,
    SynthesisError,
    Synthesizer,
    TrackingFrame,
)
from avatarsim.synthesis.two_bone import unit

SITES = ("head", "l_ankle", "r_ankle", "pelvis", "neck", "l_wrist", "r_wrist")
"""The humanoid's body17 sites the IK steers, in goal order: the tracked joints first, in
the order of :data:`TRACKED` (head, feet, root), then the spine and the wrists."""
TRACKED = ("hmd", "left_foot_tracker", "right_foot_tracker", "back_tracker")
"""Devices with a tracker-to-joint offset (eqs. 2-3), one per site of :data:`SITES`."""
HANDS = ("left_controller", "right_controller")
HAND_DEVICES = np.array([FULL_BODY.index(d) for d in HANDS])
"""Role-order indices (:data:`~render_cams.vr.FULL_BODY`) of :data:`HANDS`."""
ANALYTIC_DEVICES = np.array([FULL_BODY.index(d) for d in (*TRACKED, *HANDS)])
"""Role-order indices of the devices of the analytic solver's joints: head, feet, root
(:data:`TRACKED`), wrists (:data:`HANDS`)."""
LIMB_ENDS = np.array([1, 2, 4, 5])
"""The ankles and wrists in that order: the four limbs' goals (:data:`~synthesis.avatargo.
analytic_ik.LIMBS`)."""
POSITION_COST = np.array([10.0, 10.0, 10.0, 10.0, 0.3, 10.0, 10.0])
ORIENTATION_COST = np.array([0.1, 1.0, 1.0, 1.0, 0.0, 0.03, 0.03])
"""Head, feet, root and wrists are the paper's goals (Unity IK effectors plus root and head,
§3.4), positions first; the spine's bend is a soft hint. The root's and feet's rotations
(eq. 3) hold the pelvis and so the knees: at 0.3 a standing user's knees came out 17 deg
off (seed 0 wave) against 0.8 deg at 1.0. The wrists' and head's rotations weigh little
(mink weighs 1 rad like 1 m): with the wrists' at 0.3 the QP stuck in twisted-forearm
minima on the generator's boxing, head 9-11 cm and palms 25-30 cm off although the truth's
pose meets every goal (at 0.03: under 1 cm). Tuned on wave (seeds 0, 2) and box (seed 1).
So soft a wrist turn leaves the wrist up to ~6 deg off its goal, and the palm, 8 cm out,
up to 9 mm off the controller; hence each tick after the first aims the wrist at the
controller less the palm offset turned by the wrist's solved rotation (the last tick's),
not the goal's: the palm then sits on the controller whatever turn the IK settles on."""
ITERATIONS_PER_TICK = 2
"""QP iterations per 90 Hz tick after the first (warm start; the goals move < 2 cm a tick)."""
FIRST_ITERATIONS = 40
"""QP iterations of the first tick, from the T-pose rigidly fitted to the goals."""
OFFSET_KINDS = ("exact", "fixed")
QP_SOLVERS = {"mink": HumanoidIK, "least-squares": LeastSquaresIK}
"""Full-body IK on the humanoid's goals (:data:`SITES`): mink's QP (joint ranges as
constraints) or closed-form damped least squares on the QP's costs
(:mod:`synthesis.avatargo.least_squares_ik`: ~2.5x faster a tick, 2-3x the foot and root
error while walking, see its docstring). The first tick, 40 iterations from the rigidly
fitted T-pose, is mink's either way (least-squares steps from there left a leg 45 cm off on
the generator's box)."""
ANALYTIC = "analytic"
SOLVERS = (ANALYTIC, *QP_SOLVERS)
"""The per-tick IK: ``"analytic"`` (default), closed-form two-bone IK written here in place
of the paper's Unity IK, on its effectors (:mod:`synthesis.avatargo.analytic_ik`: root from
eqs. 2-3, spine by eq. 4, two-bone limbs, no optimisation), or one of :data:`QP_SOLVERS`,
full-body IK on the humanoid standing in for Unity's IK."""
SOLVER_LABELS = {
    ANALYTIC: "closed-form two-bone IK in place of the paper's Unity IK",
    "mink": "mink full-body IK on the humanoid in place of the paper's Unity IK",
    "least-squares": "least-squares full-body IK on the humanoid in place of the paper's Unity IK",
}
"""What each of :data:`SOLVERS` is, for every output that names it: none is the paper's
implementation (Unity's built-in IK, §3.4)."""


@dataclass(frozen=True)
class Calibration:
    """What the walk-in step stores (§3.3): see the module docstring.

    Attributes:
        roles: the identified devices.
        scale: the avatar's uniform scale.
        root_pos: ``(3,)`` the avatar's root in its walk-in T-pose.
        tracked: joint-in-device offsets of :data:`TRACKED`.
        hands: wrist-in-controller offsets (left, right).
        w0: ``(3,)`` eq. 1, back tracker to headset.
        spine0: ``(3,)`` the avatar's pelvis-to-neck vector in the T-pose.
    """

    roles: Roles
    scale: float
    root_pos: np.ndarray
    tracked: TrackerOffsets
    hands: TrackerOffsets
    w0: np.ndarray
    spine0: np.ndarray


def head_height(body: BodyDescription) -> float:
    """Height of the head joint of ``body`` standing in its rest pose."""
    sk = body.skeleton
    return body.root_height + sk.rest_positions()[sk.index(body.rig.body17["head"])][2]


def head_under(position: np.ndarray, rotation: np.ndarray, headset: Attachment) -> np.ndarray:
    """``(3,)`` the head joint under a headset at ``position (3,)``, wxyz ``rotation (4,)``
    mounted on the head as ``headset`` (device pose in the head's frame):
    ``p_head = p_hmd - R_hmd R_mount^-1 p_mount``. The joint frame's convention cancels
    (a mount re-expressed in a turned frame, :func:`~synthesis.ik_baseline.
    attachments_on_upright_rig`, gives the same head)."""
    back = quat.rotate(quat.conj(headset.rotation), headset.position)
    return position - quat.rotate(quat.normalize(rotation), back)


def _first_usable(values: np.ndarray, ok: np.ndarray, last: np.ndarray) -> np.ndarray:
    """``values (B, D, n)`` with each unusable sample replaced by the device's latest usable
    one before it in the batch, or by ``last (D, n)`` (the previous batch's)."""
    b = values.shape[0]
    latest = np.where(ok, np.arange(b)[:, None], -1)
    latest = np.maximum.accumulate(latest, axis=0)  # (B, D) index of the last usable sample
    filled = np.take_along_axis(values, np.maximum(latest, 0)[..., None], axis=0)
    return np.where((latest >= 0)[..., None], filled, last[None])


class AvatarGo(Synthesizer):
    """AvatarGo on ``avatar`` (any rig :func:`build_body` accepts), calibrated on ``walk_in``.

    Args:
        avatar: the avatar's skeleton, in its own proportions (scaled here from eye height).
        walk_in: the T-pose sample of the six devices (any order; the names say only each
            device's class, :func:`~synthesis.avatargo.calibration.device_class`).
        offsets: ``"exact"`` (AvatarGo) or ``"fixed"`` (the baseline for root and feet).
        headset: how the headset sits on the user's head (device pose in the head joint's
            frame); None: the nominal mount (:func:`~render_cams.vr.nominal_attachment`).
            The walk-in centres the avatar's head under the headset and scales the avatar
            by the head's height (§3.2: the user walks into the avatar, eyes in its eyes).
        fingers: pose the fingers on the controllers (when the avatar has finger bones).
        iterations_per_tick: IK iterations per tick after the first.
        solver: one of :data:`SOLVERS`.

    Raises:
        CalibrationError: the walk-in sample does not identify the devices.
        SynthesisError: unknown ``offsets`` or ``solver``.
    """

    name = "avatargo"

    def __init__(
        self,
        avatar: Skeleton,
        walk_in: TrackingFrame,
        offsets: str = "exact",
        headset: Attachment | None = None,
        fingers: bool = True,
        iterations_per_tick: int = ITERATIONS_PER_TICK,
        solver: str = ANALYTIC,
    ):
        if offsets not in OFFSET_KINDS:
            raise SynthesisError(f"offsets must be one of {OFFSET_KINDS}, got {offsets!r}")
        if solver not in SOLVERS:
            raise SynthesisError(f"solver must be one of {tuple(SOLVERS)}, got {solver!r}")
        self.solver = solver
        self.offsets = offsets
        positions = np.where(np.asarray(walk_in.valid)[:, None], walk_in.positions, np.nan)
        roles = identify_roles(positions, walk_in.quaternions, classes_of(walk_in.device_names))
        self.devices = tuple(walk_in.device_names[i] for i in roles.index)
        hmd = roles.index[0]
        headset = nominal_attachment("hmd", avatar) if headset is None else headset
        head = head_under(positions[hmd], walk_in.quaternions[hmd], headset)
        scale = head[2] / head_height(build_body(avatar))
        self.body = build_body(avatar.scaled(scale))
        self.grip: Grip = grip_of(self.body.skeleton)
        self.calibration = self._calibrate(roles, scale, head, positions, walk_in.quaternions)
        self.iterations_per_tick = int(iterations_per_tick)
        self.ik: HumanoidIK | None = None
        self.analytic: AnalyticIK | None = None
        if solver == ANALYTIC:
            self.analytic = AnalyticIK(self.body)
            self._arm_length = self.analytic.arm_length
            cal = self.calibration
            # The head, feet and root (TRACKED) and the wrists (HANDS) in one product.
            self._joint_offsets = TrackerOffsets(
                np.concatenate([cal.tracked.position, cal.hands.position]),
                np.concatenate([cal.tracked.rotation, cal.hands.rotation]),
            )
            self._w0_in_root, _ = unit(self.analytic.spine_to_head)  # eq. 1, the root's frame
        else:
            self._build_qp(QP_SOLVERS[solver])

        self.finger_ik = (
            FingerIK(self.body.skeleton, self.grip)
            if fingers and has_fingers(self.body.skeleton)
            else None
        )
        self.reset()

    def _build_qp(self, solver: type[HumanoidIK]) -> None:
        """The full-body IK of ``solver`` on :data:`SITES`, and the arms' sites."""
        self.ik = solver(
            self.body.model,
            SITES,
            position_cost=POSITION_COST,
            orientation_cost=ORIENTATION_COST,
            settings=IKSettings(max_iterations=self.iterations_per_tick),
        )
        arm_sites = ("l_shoulder", "r_shoulder", "l_elbow", "r_elbow", "l_wrist", "r_wrist")
        site = np.array(
            [mujoco.mj_name2id(self.body.model, mujoco.mjtObj.mjOBJ_SITE, s) for s in arm_sites]
        )
        self._shoulder_sites, self._wrist_sites = site[:2], site[4:]
        self.ik.frame_positions(self.body.model.qpos0)  # the rest pose into the sites' data
        arm = self.ik.configuration.data.site_xpos[site].reshape(3, 2, 3)
        self._arm_length = np.linalg.norm(np.diff(arm, axis=0), axis=-1).sum(0)  # (2,)

    # -- walk-in ----------------------------------------------------------------------------
    def _calibrate(
        self,
        roles: Roles,
        scale: float,
        head: np.ndarray,
        positions: np.ndarray,
        quaternions: np.ndarray,
    ) -> Calibration:
        """§3.2-3.3 on the role-ordered walk-in sample, the user's head at ``head (3,)``
        (see :class:`Calibration`)."""
        sk = self.body.skeleton
        rig = identify_rig(sk)
        heading = roles.heading
        rest = sk.rest_positions()
        joint = {n: rest[sk.index(rig.body17[n])] for n in SITES}
        p = positions[roles.index]
        q = quat.normalize(np.asarray(quaternions, float)[roles.index])
        # The avatar's head where the user's is, the feet on the floor (§3.2).
        root = head - quat.rotate(heading, joint["head"])
        root[2] = self.body.root_height
        placed = {n: root + quat.rotate(heading, v) for n, v in joint.items()}
        role = dict(zip(FULL_BODY, range(len(FULL_BODY)), strict=True))
        device = [role[d] for d in TRACKED]
        joint_pos0 = np.stack([placed[s] for s in SITES[:4]])
        heading4 = np.tile(heading, (4, 1))
        tracked = exact_offsets(p[device], q[device], joint_pos0, heading4)
        if self.offsets == "fixed":
            nominal = fixed_offsets([nominal_attachment(d, sk) for d in TRACKED[1:]], scale)
            tracked = TrackerOffsets(
                np.concatenate([tracked.position[:1], nominal.position]),
                np.concatenate([tracked.rotation[:1], nominal.rotation]),
            )
        hand = [role[d] for d in HANDS]
        hands = palm_offsets(q[hand], np.tile(heading, (2, 1)), self.grip)
        return Calibration(
            roles,
            float(scale),
            root,
            tracked,
            hands,
            w0=p[role["hmd"]] - p[role["back_tracker"]],
            spine0=placed["neck"] - placed["pelvis"],
        )

    def t_pose(self) -> np.ndarray:
        """``(nq,)`` the avatar's walk-in T-pose."""
        q = self.body.model.qpos0.copy()
        q[:3] = self.calibration.root_pos
        q[3:7] = self.calibration.roles.heading
        return q

    def t_pose_positions(self) -> np.ndarray:
        """``(J, 3)`` world joint positions of the avatar's walk-in T-pose."""
        rest = self.body.skeleton.rest_positions()
        return self.calibration.root_pos + quat.rotate(self.calibration.roles.heading, rest)

    # -- Synthesizer ------------------------------------------------------------------------
    @property
    def skeleton(self) -> Skeleton:
        return self.body.skeleton

    def settings(self) -> dict:
        return {"offsets": self.offsets, "scale": self.calibration.scale, "solver": self.solver}

    def reset_state(self) -> None:
        self._q = self.t_pose()
        self._solved = False
        self._last_pos = np.full((len(FULL_BODY), 3), np.nan)
        self._last_rot = np.tile(quat.IDENTITY, (len(FULL_BODY), 1))
        self.palm_distance: list[np.ndarray] = []
        """Per frame so far, ``(2,)`` metres from each palm's controller point to the tracked
        controller (:func:`~synthesis.avatargo.hands.palm_distance`)."""
        self.attached: list[np.ndarray] = []
        """Per frame so far, ``(2,)`` whether the controller was out of the arm's reach and
        the virtual controller drawn in the hand (:func:`~synthesis.avatargo.hands.
        out_of_reach`)."""
        if self.finger_ik is not None:
            self.finger_ik.reset()

    def goals(self, positions: np.ndarray, quaternions: np.ndarray):
        """The IK goals for device poses ``positions (B, 6, 3)``, ``quaternions (B, 6, 4)``
        in role order: positions ``(B, 7, 3)`` and wxyz orientations ``(B, 7, 4)`` of
        :data:`SITES` (eqs. 2-4 and the palm offsets)."""
        cal = self.calibration
        tracked = [FULL_BODY.index(d) for d in TRACKED]
        hand = [FULL_BODY.index(d) for d in HANDS]
        pos, rot = cal.tracked.joint_poses(positions[:, tracked], quaternions[:, tracked])
        wrist_pos, wrist_rot = cal.hands.joint_poses(positions[:, hand], quaternions[:, hand])
        w = positions[:, FULL_BODY.index("hmd")] - positions[:, FULL_BODY.index("back_tracker")]
        neck = pos[:, 3] + quat.rotate(spine_bend(cal.w0, w), cal.spine0)
        goal_pos = np.concatenate([pos, neck[:, None], wrist_pos], axis=1)
        goal_rot = np.concatenate([rot, rot[:, 3:], wrist_rot], axis=1)
        return goal_pos, goal_rot

    def advance(self, frames: FrameBatch) -> Poses:
        """The analytic solver on the whole batch at once, or the QP solvers' goals for the
        batch, then one warm-started solve per frame; the fingers frame by frame."""
        index = self.device_index(frames)
        poses = np.concatenate(
            [frames.positions.take(index, axis=1), frames.quaternions.take(index, axis=1)],
            -1,
        )  # (x.take: x[:, index] without its set-up)
        # frames.usable() of the devices read, on their poses gathered already.
        ok = np.isfinite(poses).all(-1) & frames.valid.take(index, axis=1).astype(bool)
        if ok.all():  # the common case: every device tracked, and so seen (a per-tick fast path)
            seen = ok[:, 0]  # all True (a view: np.ones' Python wrapper costs more)
        else:
            last = np.concatenate([self._last_pos, self._last_rot], -1)
            poses = _first_usable(poses, ok, last)  # (B, 6, 7) positions and rotations
            seen = np.isfinite(poses).all(-1).all(-1)  # every device tracked at least once
        pos, rot = poses[..., :3], poses[..., 3:]
        self._last_pos, self._last_rot = pos[-1], rot[-1]
        if not seen.all():  # NaN before a device is first seen
            pos = np.where(seen[:, None, None], pos, 0.0)
            rot = np.where(seen[:, None, None], rot, quat.IDENTITY)
        rot = quat.normalize(rot)
        if self.analytic is not None:
            root_pos, local = self._solve_analytic(pos, rot, seen)
        else:
            root_pos, local = self._solve_qp(pos, rot, seen)
        if self.finger_ik is not None:
            fingers = self.finger_ik
            rotations = np.empty((frames.size, *fingers.rig.joints.shape, 4))  # (B, F, 3, 4)
            for b in range(frames.size):
                fingers.advance()
                rotations[b] = fingers.rotations()
            local = local.copy()
            local[:, fingers.rig.joints] = rotations
        return Poses(root_pos, local)

    def analytic_goals(self, positions: np.ndarray, quaternions: np.ndarray) -> AnalyticGoals:
        """The analytic solver's goals for device poses ``positions (B, 6, 3)``, unit
        ``quaternions (B, 6, 4)`` in role order (eqs. 2-4 and the palm offsets)."""
        joint_pos, joint_rot = self._joint_offsets.joint_poses(
            positions.take(ANALYTIC_DEVICES, axis=1),
            quaternions.take(ANALYTIC_DEVICES, axis=1),
        )  # head, feet, root, wrists (x.take: x[:, index] without its set-up)
        # eq. 4's w_t: from the spine joint the bend turns (on the pelvis, eqs. 2-3) to the
        # head's centre (eqs. 2-3 of the headset); see synthesis.avatargo.spine.
        pelvis_mat = quat.unit_to_matrix(joint_rot[:, 3])
        w = joint_pos[:, 0] - joint_pos[:, 3] - pelvis_mat @ self.analytic.pelvis_to_spine
        return AnalyticGoals(
            joint_pos[:, 3],
            joint_rot[:, 3],
            spine_bend_in_root(self._w0_in_root, w, pelvis_mat),
            joint_rot[:, 0],
            joint_pos.take(LIMB_ENDS, axis=1),
            joint_rot.take(LIMB_ENDS, axis=1),
        )

    def _solve_analytic(self, pos: np.ndarray, rot: np.ndarray, seen: np.ndarray):
        """Root positions ``(B, 3)`` and local rotations ``(B, J, 4)`` by
        :class:`~synthesis.avatargo.analytic_ik.AnalyticIK` for the role-ordered device
        poses ``pos (B, 6, 3)``, ``rot (B, 6, 4)``; the walk-in T-pose where not ``seen``."""
        cal = self.calibration
        goals = self.analytic_goals(pos, rot)
        solved = self.analytic.solve(*goals)
        controllers = pos.take(HAND_DEVICES, axis=1)
        wrists = solved.end_pos[:, LEGS:], solved.end_mat[:, LEGS:]
        palm = palm_distance(*wrists, controllers, self.grip)
        reach = beyond_reach(solved.goal_dist[:, LEGS:], self._arm_length)
        if seen.all():
            self.palm_distance.extend(palm)
            self.attached.extend(reach)
            return solved.root_pos, solved.local_rot
        self.palm_distance.extend(palm[seen])
        self.attached.extend(reach[seen])
        t_pose = np.tile(quat.IDENTITY, (self.body.skeleton.n_joints, 1))
        t_pose[0] = cal.roles.heading
        root_pos = np.where(seen[:, None], solved.root_pos, cal.root_pos)
        return root_pos, np.where(seen[:, None, None], solved.local_rot, t_pose)

    def _solve_qp(self, pos: np.ndarray, rot: np.ndarray, seen: np.ndarray):
        """As :meth:`_solve_analytic`, by one warm-started QP-solver solve per frame."""
        goal_pos, goal_rot = self.goals(pos, rot)
        qpos = np.empty((seen.size, self.body.model.nq))
        data = self.ik.configuration.data
        hand = [FULL_BODY.index(d) for d in HANDS]
        for b in range(seen.size):
            if seen[b]:
                start, steps, solve = self._q, self.iterations_per_tick, self.ik.solve_frame
                if not self._solved:  # the first goals may be far from the walk-in T-pose
                    start, steps = self.ik.fitted_root(goal_pos[b]), FIRST_ITERATIONS
                    solve = partial(HumanoidIK.solve_frame, self.ik)  # mink: see QP_SOLVERS
                else:  # the palm on the controller, whatever wrist turn the soft goal left
                    held = data.site_xmat[self._wrist_sites].reshape(2, 3, 3)
                    goal_pos[b, 5:] = pos[b, hand] - (held @ self.grip.palm[..., None])[..., 0]
                self._solved = True
                self._q, _, _ = solve(goal_pos[b], start, goal_rot[b], steps)
                wrist = data.site_xpos[self._wrist_sites]
                wrist_rot = data.site_xmat[self._wrist_sites].reshape(2, 3, 3)
                self.palm_distance.append(palm_distance(wrist, wrist_rot, pos[b, hand], self.grip))
                shoulders = data.site_xpos[self._shoulder_sites]
                self.attached.append(out_of_reach(shoulders, goal_pos[b, 5:], self._arm_length))
            qpos[b] = self._q
        motion = motion_from_qpos(self.body, qpos, DEFAULT_RATE_HZ)
        return motion.root_pos, motion.local_rot

    def run(self, stream: TrackingStream) -> Motion:
        # The QPs are small: BLAS threads cost more than they save (see avatar_models.body.ik).
        with threadpool_limits(1, user_api="blas"):
            return super().run(stream)
