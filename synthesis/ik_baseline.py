"""``IKBaseline``: a VRIK-like full-body IK from a headset and two controllers (CoolMoves §4.1.1).

The paper's baseline is RootMotion Final IK's VRIK: the head and hands are solved to the
tracked devices, the spine bends to connect them, the legs stand neutral and take procedural
steps under the moving body. Ours does the same on the MuJoCo humanoid of
:mod:`avatar_models.body`, with mink (:class:`~avatar_models.body.ik.HumanoidIK`):

- targets of the head and wrist sites: the device poses with the nominal device attachments
  (:func:`render_cams.vr.nominal_attachment`) taken off, i.e. where the joints must be for a
  user calibrated to the rig (VRIK is calibrated the same way), position and orientation;
- a pelvis hint below the head: the rest head-to-pelvis offset turned by the head's heading,
  so the spine bends only as much as the head and hands need;
- feet from a procedural stepper (:class:`Stepper`): each foot stays planted until the
  neutral stance under the pelvis hint (raised with a climbing head) has moved away from it
  by more than :data:`STEP_TRIGGER_M`, then steps there in :data:`STEP_DURATION_S` on a
  raised arc, one foot at a time, as VRIK's locomotion does.

Each tick is one warm-started IK solve of a few QP iterations (VRIK also iterates once or
twice per frame and relies on temporal coherence). Missing devices hold their last pose;
before the first tracked sample the avatar stands in its rest pose at the origin.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from threadpoolctl import threadpool_limits

from avatar_models import Motion, Skeleton, quat
from avatar_models.body import build_body
from avatar_models.body.ik import HumanoidIK, IKSettings, humanoid_model, motion_from_qpos
from avatar_models.measure import standing_height
from render_cams import TrackingStream
from render_cams.vr import HEADSET_AND_CONTROLLERS, Attachment, nominal_attachment
from synthesis.base import Pose, SynthesisError, Synthesizer, TrackingFrame, on_clock

STEERED_SITES = ("head", "l_wrist", "r_wrist", "pelvis", "l_ankle", "r_ankle")
"""The humanoid's body17 sites the IK steers, in target order."""
DEVICE_SITES = {"hmd": "head", "left_controller": "l_wrist", "right_controller": "r_wrist"}

POSITION_COST = np.array([10.0, 1.0, 1.0, 0.05, 0.05, 0.05])
"""Tracked joints dominate, the head most (VRIK locks the head: an out-of-reach hand must not
drag the body along); the pelvis hint and the stepper's feet are soft (VRIK's body and
leg weights are likewise below the head and hand weights)."""
ORIENTATION_COST = np.array([0.1, 0.01, 0.01, 0.0, 0.0, 0.0])
"""Head and hand orientation follow their devices far more loosely than their positions
(mink weighs 1 rad like 1 m): stronger hand weights trap the QP in poses centimetres off
the hand positions when a controller is turned far from the rest forearm."""

STEP_TRIGGER_M = 0.12
"""Distance between a planted foot and its neutral stance that starts a step
(VRIK's default ``stepThreshold`` is 0.4 m of body motion split over two feet; a smaller
value keeps the feet under a walking body)."""
STEP_DURATION_S = 0.25
"""Duration of one procedural step (VRIK's default ``stepSpeed`` of 3 steps per second)."""
STEP_HEIGHT_M = 0.05
"""Apex of the foot's arc above the floor level during a step."""
ITERATIONS_PER_TICK = 4
"""QP iterations per 90 Hz tick after the first (warm start; enough to stay within 1 cm of
reachable targets at VR motion speeds, measured on the generator's activities)."""


@dataclass
class Stepper:
    """Procedural feet: planted until the neutral stance moves away, then one step there.

    State per foot: ``planted (2, 3)`` position on the floor, and the step in progress
    (start, goal, elapsed time) of at most one foot.
    """

    planted: np.ndarray
    stepping: int = -1
    start: np.ndarray | None = None
    goal: np.ndarray | None = None
    elapsed: float = 0.0

    def advance(self, neutral: np.ndarray, velocity: np.ndarray, dt: float) -> np.ndarray:
        """Feet positions ``(2, 3)`` after ``dt`` seconds, given the neutral stance ``(2, 3)``
        and the body's horizontal velocity ``(3,)`` (a step lands where the body will be)."""
        if self.stepping >= 0:
            self.elapsed += dt
            s = min(self.elapsed / STEP_DURATION_S, 1.0)
            blend = s * s * (3.0 - 2.0 * s)  # smoothstep: zero speed at lift-off and landing
            foot = self.start + blend * (self.goal - self.start)
            foot[2] += STEP_HEIGHT_M * np.sin(np.pi * s)
            self.planted[self.stepping] = foot
            if s >= 1.0:
                self.planted[self.stepping] = self.goal
                self.stepping = -1
        if self.stepping < 0:
            gap = np.linalg.norm(neutral - self.planted, axis=1)
            foot = int(np.argmax(gap))
            if gap[foot] > STEP_TRIGGER_M:
                self.stepping, self.elapsed = foot, 0.0
                self.start = self.planted[foot].copy()
                self.goal = neutral[foot] + 0.5 * STEP_DURATION_S * velocity
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
        self._rest_sites = rest
        self.reset()

    @property
    def skeleton(self) -> Skeleton:
        return self.body.skeleton

    def reset(self) -> None:
        self._q = self.ik.posture.copy()
        self._solved = False
        self._joints: np.ndarray | None = None  # (3, 7) last head/wrist positions + wxyz
        self._stepper: Stepper | None = None
        self._last_time: float | None = None
        self._last_pelvis: np.ndarray | None = None

    def _device_index(self, names: tuple[str, ...]) -> np.ndarray:
        missing = [d for d in HEADSET_AND_CONTROLLERS if d not in names]
        if missing:
            raise SynthesisError(f"the IK baseline needs devices {missing}; the stream has {names}")
        return np.array([names.index(d) for d in HEADSET_AND_CONTROLLERS])

    def joint_targets(self, positions: np.ndarray, quaternions: np.ndarray) -> np.ndarray:
        """Head, left and right wrist ``(3, 7)`` (position, wxyz) from the device poses
        ``positions (3, 3)`` and ``quaternions (3, 4)`` (hmd, left, right controller):
        ``R_joint = R_device R_att^-1``, ``p_joint = p_device - R_joint p_att``."""
        att_pos = np.stack([a.position for a in self._attachments])
        att_rot = np.stack([a.rotation for a in self._attachments])
        rot = quat.normalize(quat.mul(quat.normalize(quaternions), quat.conj(att_rot)))
        return np.concatenate([positions - quat.rotate(rot, att_pos), rot], axis=1)

    def _solve(self, frame: TrackingFrame) -> np.ndarray:
        """The qpos ``(nq,)`` for one tracking sample (state advanced)."""
        dt = 1.0 / 90.0
        if self._last_time is not None:
            if not frame.timestamp > self._last_time:
                return self._q  # a late or repeated sample: already past it
            dt = float(frame.timestamp) - self._last_time
        if np.isfinite(frame.timestamp):
            self._last_time = float(frame.timestamp)
        index = self._device_index(frame.device_names)
        ok = frame.usable()[index]
        fresh = self.joint_targets(
            np.where(ok[:, None], frame.positions[index], 0.0),
            np.where(ok[:, None], frame.quaternions[index], quat.IDENTITY),
        )
        if self._joints is None:
            if not ok[0]:
                return self._q  # nothing to stand under yet: rest pose
            self._joints = np.where(ok[:, None], fresh, np.nan)
        self._joints = np.where(ok[:, None], fresh, self._joints)
        head_pos, head_rot = self._joints[0, :3], self._joints[0, 3:]
        heading = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), quat.yaw(head_rot))
        pelvis = head_pos + quat.rotate(heading, self._rest_head_to_pelvis)
        neutral = pelvis + quat.rotate(heading, self._rest_pelvis_to_feet)
        # The feet stand on the floor, or on whatever raises a head above its standing
        # height (a ladder rung, a step): a crouch bends the knees, a climb lifts the feet.
        support = max(0.0, head_pos[2] - self._rest_sites[0, 2])
        neutral[:, 2] = self._rest_sites[4:, 2] + support
        velocity = np.zeros(3)
        if self._last_pelvis is not None and dt > 0:
            velocity[:2] = (pelvis - self._last_pelvis)[:2] / dt
        self._last_pelvis = pelvis
        if self._stepper is None:
            self._stepper = Stepper(neutral.copy())
        feet = self._stepper.advance(neutral, velocity, dt)
        positions = np.concatenate([self._joints[:, :3], pelvis[None], feet])
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

    def step(self, frame: TrackingFrame) -> Pose:
        pose = motion_from_qpos(self.body, self._solve(frame)[None], 90.0)
        return Pose(pose.root_pos[0], pose.local_rot[0])

    def run(self, stream: TrackingStream) -> Motion:
        """Every tick of the re-clocked stream in order; the same result as :meth:`step`."""
        clocked = on_clock(stream)
        self.reset()
        # The QPs are small: BLAS threads cost more than they save (see avatar_models.body.ik).
        with threadpool_limits(1, user_api="blas"):
            qpos = np.stack(
                [
                    self._solve(TrackingFrame.from_stream(clocked, i))
                    for i in range(clocked.n_samples)
                ]
            )
        motion = motion_from_qpos(self.body, qpos, float(clocked.meta["rate_hz"]))
        return motion.replace(meta={"method": self.name, "stream": clocked.meta})
