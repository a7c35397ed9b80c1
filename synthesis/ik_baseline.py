"""``IKBaseline``: a VRIK-like full-body IK from a headset and two controllers (CoolMoves §4.1.1).

The paper's baseline is RootMotion Final IK's VRIK: the head and hands are solved to the
tracked devices, the spine bends to connect them, the legs stand neutral and take procedural
steps under the moving body. Ours does the same on the MuJoCo humanoid of
:mod:`avatar_models.body`, with mink (:class:`~avatar_models.body.ik.HumanoidIK`):

- targets of the head and wrist sites: the device poses with the nominal device attachments
  (:func:`render_cams.vr.nominal_attachment`) taken off, i.e. where the joints must be for a
  user calibrated to the rig (VRIK is calibrated the same way), position and orientation;
- a pelvis hint below the head (:meth:`IKBaseline.body_targets`): the rest body hung from
  the head, turned to the face's heading and leaned forward once the head pitches past a
  dead zone (a face-down swimmer lies horizontal); a lowered head crouches the legs;
- feet from a procedural stepper (:class:`Stepper`): each foot stays planted until the
  neutral stance under the pelvis hint (raised with a climbing head) has moved away from it
  by more than :data:`STEP_TRIGGER_M`, then steps to where the stance will be, half a step
  ahead, one foot at a time, as VRIK's locomotion does; cadence and swing height grow with
  the body's speed. A body leaning past :data:`GROUNDED_LEAN_RAD` does not stand: its feet
  move with it;
- soft targets kept consistent with the tracked ones: feet within a leg of the pelvis hint,
  hands within an arm (plus :data:`ARM_REACH_SLACK_M`) of the shoulders. The QP's costs are
  squared, so one far soft target (a foot left behind by a running body) outweighed the
  head's and hands' centimetres and held them 4 cm off on a noise-free run.

Each tick is one warm-started IK solve of a few QP iterations (VRIK also iterates once or
twice per frame and relies on temporal coherence). Missing devices hold their last pose;
before the first tracked sample the avatar stands in its rest pose at the origin.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
from threadpoolctl import threadpool_limits

from avatarsim.avatar_models import Motion, Skeleton, body17, quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.body.ik import HumanoidIK, IKSettings, humanoid_model, motion_from_qpos
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams import TrackingStream
from avatarsim.render_cams.vr import HEADSET_AND_CONTROLLERS, Attachment, nominal_attachment
from avatarsim.synthesis.base import DEFAULT_RATE_HZ, FrameBatch, Poses, SynthesisError, Synthesizer

STEERED_SITES = ("head", "l_wrist", "r_wrist", "pelvis", "l_ankle", "r_ankle")
"""The humanoid's body17 sites the IK steers, in target order."""
DEVICE_SITES = {"hmd": "head", "left_controller": "l_wrist", "right_controller": "r_wrist"}

POSITION_COST = np.array([10.0, 1.0, 1.0, 0.05, 0.05, 0.05])
"""Tracked joints dominate, the head most (VRIK locks the head: an out-of-reach hand must not
drag the body along); the pelvis hint and the stepper's feet are soft (VRIK's body and
leg weights are likewise below the head and hand weights). Soft targets are kept within
reach of each other (:meth:`IKBaseline.body_targets`): the costs are squared, so a foot
left half a metre behind a running body would outweigh centimetres of head error."""
ORIENTATION_COST = np.array([0.1, 0.01, 0.01, 0.0, 0.0, 0.0])
"""Head and hand orientation follow their devices far more loosely than their positions
(mink weighs 1 rad like 1 m): stronger hand weights trap the QP in poses centimetres off
the hand positions when a controller is turned far from the rest forearm."""

ARM_REACH_SLACK_M = 0.15
"""Reach beyond the straight arm that a hand target may ask for (our choice: what a trunk
lean and the shoulder girdle add, about a hand's length); farther targets are pulled in."""
LEAN_DEAD_ZONE_RAD = np.radians(30.0)
LEAN_FULL_RAD = np.radians(75.0)
"""Trunk lean from the head's pitch (our choice, in the spirit of VRIK's body tilt): a head
pitched less than the dead zone (looking down at a ball or a hand) leaves the trunk upright;
beyond it the trunk leans, reaching horizontal at :data:`LEAN_FULL_RAD` (a face-down head,
as when lying or swimming)."""
GROUNDED_LEAN_RAD = np.radians(60.0)
"""A trunk leaning further than this does not stand on its feet (lying, swimming, crawling):
the feet then stay in their stance relative to the body instead of planting on the floor."""
STEP_TRIGGER_M = 0.12
"""Distance between a planted foot and its neutral stance that starts a step
(VRIK's default ``stepThreshold`` is 0.4 m of body motion split over two feet; a smaller
value keeps the feet under a walking body)."""
CADENCE_STEPS_PER_S = (1.1, 0.55)
"""Step frequency ``a + b v`` (steps/s) at horizontal speed ``v`` (m/s): about 1.8 steps/s
walking at 1.3 m/s and 2.9 steps/s running at 3.3 m/s (Dean 1965; Cavanagh & Kram 1989
report 2.7-3.0 steps/s at 3-4 m/s)."""
VRIK_STEP_SPEED = 3.0
"""VRIK's default ``Locomotion.stepSpeed`` (FinalIK ``IKSolverVRLocomotion``): a step's progress
advances by ``stepSpeed * dt``, so a step lasts ``1 / stepSpeed`` s, and each step draws its
speed uniformly from ``[stepSpeed, 1.5 stepSpeed]``, i.e. 0.22-0.33 s per step."""
MAX_SWING_S = 1.0 / (1.5 * VRIK_STEP_SPEED)
"""Longest swing of one foot: a step takes ``min(1 / cadence, MAX_SWING_S)``, VRIK's quickest
step (0.222 s, :data:`VRIK_STEP_SPEED`; deterministic, where VRIK draws at random), taken
from VRIK rather than tuned on the generator's test folds. Quick swings are what
one-foot-at-a-time stepping needs to keep up without a flight phase: a biomechanical swing
time (0.4 s) leaves a running body's feet behind."""
STEP_HEIGHT_M = (0.05, 0.1, 0.35)
"""Apex of the foot's arc above its planted height: ``clip(b v, lo, hi)`` as ``(lo, b, hi)``
(our choice: about 0.13 m walking, 0.33 m running, the swing-foot heights of typical gait)."""
ITERATIONS_PER_TICK = 4
"""QP iterations per 90 Hz tick after the first (warm start; enough to stay within 1 cm of
reachable targets at VR motion speeds, measured on the generator's activities)."""


VELOCITY_SMOOTHING_S = 0.1
"""Time constant of the body velocity that sizes the steps (our choice: a tenth of a step)."""

_X, _Y, _Z = np.eye(3)


def trunk_lean(head_pitch: float) -> float:
    """Forward trunk lean (radians, 0 upright, pi/2 horizontal) for a head pitched forward by
    ``head_pitch`` radians (:data:`LEAN_DEAD_ZONE_RAD`, :data:`LEAN_FULL_RAD`)."""
    share = (head_pitch - LEAN_DEAD_ZONE_RAD) / (LEAN_FULL_RAD - LEAN_DEAD_ZONE_RAD)
    return 0.5 * np.pi * float(np.clip(share, 0.0, 1.0))


def _clip_norm(v: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """Rows of ``v (N, 3)`` shortened to at most ``limit (N, 1)``."""
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return v * np.minimum(1.0, limit / np.maximum(norm, 1e-12))


def cadence(speed: float) -> float:
    """Steps per second at horizontal ``speed`` m/s (:data:`CADENCE_STEPS_PER_S`)."""
    return CADENCE_STEPS_PER_S[0] + CADENCE_STEPS_PER_S[1] * speed


def body_frame(positions: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """``(3, 3)`` rotation whose columns are the forward, left and up axes of the body posed
    at joint ``positions (J, 3)`` of ``skeleton`` (up: pelvis to neck; left: right to left
    shoulder, made orthogonal to up)."""
    joints = positions[identify_rig(skeleton).body17_indices(skeleton)]
    at = dict(zip(body17.BODY17, joints, strict=True))
    up = at["neck"] - at["pelvis"]
    up /= np.linalg.norm(up)
    left = at["l_shoulder"] - at["r_shoulder"]
    left -= (left @ up) * up
    left /= np.linalg.norm(left)
    return np.stack([np.cross(left, up), left, up], axis=1)


def rest_body_frame(skeleton: Skeleton) -> np.ndarray:
    """:func:`body_frame` of ``skeleton``'s rest pose.

    Near the identity for a rig whose rest pose stands facing +X (the avatar rig, CMU, the
    generator's); a rig stored lying or turned (Bandai's rest pose lies along +Y, as its
    BVH's Y-up frame) gives the turn that stands it up.
    """
    return body_frame(skeleton.rest_positions(), skeleton)


def stands_upright(skeleton: Skeleton) -> bool:
    """Whether ``skeleton``'s rest pose stands (its trunk within 25 deg of +Z, facing within
    25 deg of +X): its joint frames are then those the IK's heading and lean assume."""
    frame = rest_body_frame(skeleton)
    return bool(frame[2, 2] > np.cos(np.radians(25.0)) and frame[0, 0] > np.cos(np.radians(25.0)))


def attachments_on_upright_rig(
    attachments: Sequence[Attachment], source: Skeleton
) -> list[Attachment]:
    """Device attachments measured in the joint frames of ``source`` re-expressed in the
    frames of a rig whose rest pose stands facing +X (the IK's), for the same body.

    A joint frame of ``source`` is its upright counterpart turned by ``F`` (the rest frames
    of one body differ by the turn that stands the rest pose up, :func:`rest_body_frame`):
    ``R_device = R_source R_att = R_upright F^T R_att``, so the attachment there is
    ``F^T R_att`` with offset ``F^T p_att``. Without this a Bandai headset's "forward" is
    the head's sideways axis and its "up" points ahead: the IK read every standing frame as
    a face-down body and laid it down (126 cm lower-body error on Bandai dataset-2).
    """
    turn = rest_body_frame(source).T
    q_turn = quat.from_matrix(turn)
    return [
        Attachment(a.joint, turn @ a.position, quat.mul(q_turn, a.rotation)) for a in attachments
    ]


@dataclass
class Stepper:
    """Procedural feet: planted until the neutral stance moves away, then one step there.

    Step duration and swing height follow the body's speed (:func:`cadence`,
    :data:`STEP_HEIGHT_M`); one foot swings at a time, so a moving body alternates its feet.
    State per foot: ``planted (2, 3)`` position, and the step in progress (start, goal,
    duration, elapsed time, apex) of at most one foot.
    """

    planted: np.ndarray
    stepping: int = -1
    start: np.ndarray | None = None
    goal: np.ndarray | None = None
    duration: float = 1.0
    apex: float = 0.0
    elapsed: float = 0.0

    def advance(
        self, neutral: np.ndarray, velocity: np.ndarray, dt: float, grounded: bool = True
    ) -> np.ndarray:
        """Feet positions ``(2, 3)`` after ``dt`` seconds, given the neutral stance ``(2, 3)``
        and the body's horizontal velocity ``(3,)``. A step lands where the stance will be
        when it lands, plus half a step: the body then passes over the planted foot while
        the other swings, from half a step ahead to half a step behind. Feet that are not
        ``grounded`` (a body lying or floating) move with the body, in their stance."""
        if not grounded:
            self.planted, self.stepping = neutral.copy(), -1
            return self.planted.copy()
        if self.stepping >= 0:
            self.elapsed += dt
            s = min(self.elapsed / self.duration, 1.0)
            blend = s * s * (3.0 - 2.0 * s)  # smoothstep: zero speed at lift-off and landing
            foot = self.start + blend * (self.goal - self.start)
            foot[2] += self.apex * np.sin(np.pi * s)
            self.planted[self.stepping] = foot
            if s >= 1.0:
                self.planted[self.stepping] = self.goal
                self.stepping = -1
        if self.stepping < 0:
            gap = np.linalg.norm(neutral - self.planted, axis=1)
            foot = int(np.argmax(gap))
            if gap[foot] > STEP_TRIGGER_M:
                speed = float(np.linalg.norm(velocity[:2]))
                lo, gain, hi = STEP_HEIGHT_M
                self.stepping, self.elapsed = foot, 0.0
                self.duration = min(1.0 / cadence(speed), MAX_SWING_S)
                self.apex = float(np.clip(gain * speed, lo, hi))
                self.start = self.planted[foot].copy()
                self.goal = neutral[foot] + 1.5 * self.duration * velocity
        return self.planted.copy()


class IKBaseline(Synthesizer):
    """VRIK-like full-body IK on the humanoid of ``skeleton`` scaled to the user's height.

    Args:
        skeleton: the output rig (any rig :func:`avatar_models.body.build_body` accepts); use
            the evaluation's rig so errors are measured on the same joints as other methods.
        user_height_m: the user's standing height (as :func:`standing_height` measures it);
            None keeps the skeleton's size.
        calibration: the device-on-joint attachments of the user (hmd, left, right
            controller), as a calibration would find them; default: the nominal attachments
            on ``skeleton``. Only their positions are used when ``follow_orientation`` is off.
        follow_orientation: steer head and hand orientations too. Turn it off when the
            calibration comes from another rig, whose joint frames differ from the humanoid's.
        iterations_per_tick: QP iterations per tick after the first.
    """

    name = "ik"
    devices = HEADSET_AND_CONTROLLERS

    def __init__(
        self,
        skeleton: Skeleton,
        user_height_m: float | None = None,
        calibration: Sequence[Attachment] | None = None,
        follow_orientation: bool = True,
        iterations_per_tick: int = ITERATIONS_PER_TICK,
    ):
        if user_height_m is not None:
            skeleton = skeleton.scaled(float(user_height_m) / standing_height(skeleton))
        self.body = build_body(skeleton)
        self.iterations_per_tick = int(iterations_per_tick)
        self.ik = HumanoidIK(
            humanoid_model(self.body),
            STEERED_SITES,
            position_cost=POSITION_COST,
            orientation_cost=ORIENTATION_COST if follow_orientation else 0.0,
            settings=IKSettings(max_iterations=self.iterations_per_tick),
        )
        self._attachments = (
            list(calibration)
            if calibration is not None
            else [nominal_attachment(d, self.body.skeleton) for d in HEADSET_AND_CONTROLLERS]
        )
        if len(self._attachments) != len(HEADSET_AND_CONTROLLERS):
            raise SynthesisError("the calibration needs one attachment per hmd and controller")
        rest = self.ik.frame_positions(self.ik.posture)
        self._rest_head_to_pelvis = rest[3] - rest[0]
        self._rest_pelvis_to_feet = rest[4:] - rest[3]
        self._leg_reach = np.linalg.norm(self._rest_pelvis_to_feet, axis=1)[:, None]
        sites = self.ik.configuration.data.site_xpos  # every body17 site, at the rest posture
        site = {
            n: sites[mujoco.mj_name2id(self.ik.model, mujoco.mjtObj.mjOBJ_SITE, n)].copy()
            for n in ("l_shoulder", "l_elbow", "l_wrist", "r_shoulder", "r_elbow", "r_wrist")
        }
        self._rest_head_to_shoulders = np.stack([site["l_shoulder"], site["r_shoulder"]]) - rest[0]
        self._arm_reach = ARM_REACH_SLACK_M + np.array(
            [
                [
                    np.linalg.norm(site[f"{s}_elbow"] - site[f"{s}_shoulder"])
                    + np.linalg.norm(site[f"{s}_wrist"] - site[f"{s}_elbow"])
                ]
                for s in "lr"
            ]
        )
        self._rest_sites = rest
        self.reset()

    @property
    def skeleton(self) -> Skeleton:
        return self.body.skeleton

    def reset_state(self) -> None:
        self._q = self.ik.posture.copy()
        self._solved = False
        self._joints: np.ndarray | None = None  # (3, 7) last head/wrist positions + wxyz
        self._stepper: Stepper | None = None
        self._previous_time: float | None = None
        self._last_pelvis: np.ndarray | None = None
        self._velocity = np.zeros(3)

    def joint_targets(self, positions: np.ndarray, quaternions: np.ndarray) -> np.ndarray:
        """Head, left and right wrist ``(3, 7)`` (position, wxyz) from the device poses
        ``positions (3, 3)`` and ``quaternions (3, 4)`` (hmd, left, right controller):
        ``R_joint = R_device R_att^-1``, ``p_joint = p_device - R_joint p_att``."""
        att_pos = np.stack([a.position for a in self._attachments])
        att_rot = np.stack([a.rotation for a in self._attachments])
        rot = quat.normalize(quat.mul(quat.normalize(quaternions), quat.conj(att_rot)))
        return np.concatenate([positions - quat.rotate(rot, att_pos), rot], axis=1)

    def body_targets(self, head_pos: np.ndarray, head_rot: np.ndarray):
        """Pelvis hint ``(3,)``, neutral stance of the feet ``(2, 3)``, whether the body
        stands on them (trunk lean below :data:`GROUNDED_LEAN_RAD`) and the body's turn
        from its rest pose (wxyz), under a head at
        ``head_pos (3,)`` turned by ``head_rot`` (wxyz, the head joint's global rotation).

        The rest body hangs from the head, turned to the head's heading and leaned forward
        by :func:`trunk_lean`; the feet continue the trunk line (legs straight below an
        upright pelvis, trailing behind a horizontal one) but never below the floor: a
        lowered head bends the knees (crouch), a raised one lifts the feet (a rung, a step).
        """
        fwd = quat.rotate(head_rot, _X)
        up = quat.rotate(head_rot, _Z)
        # Heading: the face's forward axis for an upright head, its up axis for a face-down
        # one (whose forward axis is vertical, and turns sideways when a swimmer breathes).
        upright = abs(float(up[2]))
        facing = upright * fwd[:2] + (1.0 - upright) * up[:2]
        heading = float(np.arctan2(facing[1], facing[0]))
        forward_tilt = float(np.arccos(np.clip(up[2], -1.0, 1.0)))
        if np.dot(up[:2], facing) < 0:  # head tilted back (looking up): the trunk stays upright
            forward_tilt = 0.0
        lean = trunk_lean(forward_tilt)
        body = quat.mul(quat.from_axis_angle(_Z, heading), quat.from_axis_angle(_Y, lean))
        pelvis = head_pos + quat.rotate(body, self._rest_head_to_pelvis)
        neutral = pelvis + quat.rotate(body, self._rest_pelvis_to_feet)
        neutral[:, 2] = np.maximum(neutral[:, 2], self._rest_sites[4:, 2])
        return pelvis, neutral, lean < GROUNDED_LEAN_RAD, body

    def _solve(
        self, timestamp: float, positions: np.ndarray, quaternions: np.ndarray, ok: np.ndarray
    ) -> np.ndarray:
        """The qpos ``(nq,)`` after one tracking sample of the hmd and both controllers:
        ``positions (3, 3)``, ``quaternions (3, 4)``, usable ``ok (3,)`` (state advanced)."""
        dt = 1.0 / 90.0
        if self._previous_time is not None:
            dt = float(timestamp) - self._previous_time
        if np.isfinite(timestamp):
            self._previous_time = float(timestamp)
        fresh = self.joint_targets(
            np.where(ok[:, None], positions, 0.0),
            np.where(ok[:, None], quaternions, quat.IDENTITY),
        )
        if self._joints is None:
            if not ok[0]:
                return self._q  # nothing to stand under yet: rest pose
            self._joints = np.where(ok[:, None], fresh, np.nan)
        self._joints = np.where(ok[:, None], fresh, self._joints)
        pelvis, neutral, grounded, body = self.body_targets(
            self._joints[0, :3], self._joints[0, 3:]
        )
        if self._last_pelvis is not None and dt > 0:
            # Smoothed over VELOCITY_SMOOTHING_S: the step goals must not jitter with the head.
            alpha = min(1.0, dt / VELOCITY_SMOOTHING_S)
            moved = np.array([*((pelvis - self._last_pelvis)[:2] / dt), 0.0])
            self._velocity += alpha * (moved - self._velocity)
        self._last_pelvis = pelvis
        if self._stepper is None:
            self._stepper = Stepper(neutral.copy())
        feet = self._stepper.advance(neutral, self._velocity, dt, grounded)
        # A planted foot the body has run away from stays where it is in the stepper, but its
        # target comes no farther from the pelvis than the straight leg (reachable: no fight).
        reach = pelvis + _clip_norm(feet - pelvis, self._leg_reach)
        # Hands no farther from their shoulders than the arm (plus the trunk's lean): an
        # out-of-reach controller is reached straight at, without dragging the head along.
        shoulders = self._joints[0, :3] + quat.rotate(body, self._rest_head_to_shoulders)
        hands = shoulders + _clip_norm(self._joints[1:, :3] - shoulders, self._arm_reach)
        positions = np.concatenate([self._joints[:1, :3], hands, pelvis[None], reach])
        orientations = np.tile(quat.IDENTITY, (len(STEERED_SITES), 1))
        orientations[:3] = self._joints[:, 3:]
        # Hands never seen yet: no target (NaN rows are dropped by the solver).
        positions[:3][np.isnan(self._joints[:, 0])] = np.nan
        first = not self._solved
        self._solved = True
        start = self.ik.fitted_root(positions) if first else self._q
        iterations = 4 * self.iterations_per_tick if first else self.iterations_per_tick
        self._q, _, _ = self.ik.solve_frame(positions, start, orientations, iterations)
        return self._q

    def advance(self, frames: FrameBatch) -> Poses:
        """One warm-started solve per frame, in order (each starts from the previous one)."""
        index = self.device_index(frames)
        ok = frames.usable()[:, index]
        qpos = np.stack(
            [
                self._solve(t, p[index], q[index], usable)
                for t, p, q, usable in zip(
                    frames.timestamps, frames.positions, frames.quaternions, ok, strict=True
                )
            ]
        )
        motion = motion_from_qpos(self.body, qpos, DEFAULT_RATE_HZ)
        return Poses(motion.root_pos, motion.local_rot)

    def run(self, stream: TrackingStream) -> Motion:
        # The QPs are small: BLAS threads cost more than they save (see avatar_models.body.ik).
        with threadpool_limits(1, user_api="blas"):
            return super().run(stream)
