"""Finger IK on the controller (AvatarGo §3.4 "Fingers IK", eqs. 5-7).

The controller's handle is a capsule SDF (eq. 5): ``sdf(p) = |v1 - v2 h| - r`` with
``v1 = p - s``, ``v2 = e - s``, ``h = clamp(v1.v2 / v2.v2, 0, 1)``. Each of the 10 fingers
``f`` has three joints ``j`` with an open-to-closed parameter ``t_f^j in [0, 1]``: the joint
flexes by ``t_f^j`` times its closed angle (:data:`CLOSED_DEG`) about the finger's
flexion axis. The cost of a finger (eq. 6) sums the SDF over the points its three joints
move (the two inner joints and the tip), each made ``|.|`` and multiplied by
:data:`PENETRATION_PENALTY` when negative (inside the handle), plus, optionally, the thumb
tip's distance to a button. Gradient descent (eq. 7) ``t <- t - eta dd_f/dt``, clipped to
``[0, 1]`` (the finger limits: the closed angles are within the AAOS ranges of motion).

Gradient: **numeric (central differences), as the paper does**, not torch autograd. A
finger's cost depends only on its own three parameters, so the 6 perturbed evaluations of
all 10 fingers are one vectorised numpy call on ``(7, 10, 3)`` points: tens of microseconds,
where a torch graph on 30 scalars costs ~0.3 ms of per-op overhead per iteration and would
spend the whole step's 1 ms latency aim. Beyond the paper (our addition): a per-finger
step size that halves when a step would raise the cost and grows again when it lowers it,
so that a finger settles on the handle instead of jittering across the surface (the
paper's trade-off on ``eta``).

Poses are expressed in each hand's frame (the wrist joint): the controller is fixed there
(:mod:`synthesis.avatargo.hands`), so a warm-started solve stays converged from frame to
frame. The fingers are the avatar rig's bones (the humanoid fixes them into the hand), so
finger IK poses the avatar rig's fingers and is evaluated on its forward kinematics.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from avatarsim.avatar_models import Skeleton, quat
from avatarsim.synthesis.avatargo.hands import CONTROLLER_RADIUS_M, PALM_NORMAL, Grip, finger_joint

CLOSED_DEG = np.array([[15.0, 50.0, 80.0], *[[90.0, 100.0, 90.0]] * 4])
"""Closed angle of each joint (degrees), thumb first then index to little finger: the AAOS
(1965) normal flexion ranges (thumb CMC ~15, MCP 50, IP 80; fingers MCP 90, PIP 100,
DIP 90), so every ``t`` in [0, 1] is within the joint's limits."""
PENETRATION_PENALTY = 10.0
"""Factor on the SDF of a point inside the handle (our choice: a point 1 mm inside costs as
much as one 1 cm away, so the optimum lies on the surface, outside)."""
LEARNING_RATE = 2.0
"""Initial ``eta`` of eq. 7 (units of t per metre of cost; our choice)."""
MAX_LEARNING_RATE = 50.0 * LEARNING_RATE
"""Cap of the growing step size (a full open-to-closed swing per step at ~2 cm of cost)."""
GRADIENT_STEP = 1e-4
"""Central-difference step in ``t``."""
SETTLE_ITERATIONS = 150
"""Iterations of the first solve from the open hand (measured: converged by ~80)."""
ETA_FLOOR = 1e-3 * LEARNING_RATE
"""Least step size at the start of a frame's solve: a finger whose step collapsed probes
again (our choice)."""


@dataclass(frozen=True, eq=False)
class FingerRig:
    """The 10 fingers (left thumb..little, right thumb..little) in their hands' frames.

    Attributes:
        joints: ``(F, 3)`` skeleton indices of each finger's three joints.
        base: ``(F, 3)`` rest position of the first joint (hand frame).
        segments: ``(F, 3, 3)`` rest bone vectors: joint 1 -> 2, 2 -> 3, 3 -> tip.
        axis: ``(F, 3)`` unit flexion axis (turns the finger towards the palm).
        closed: ``(F, 3)`` closed angles, radians.
        hand: ``(F,)`` 0 for the left hand, 1 for the right.
    """

    joints: np.ndarray
    base: np.ndarray
    segments: np.ndarray
    axis: np.ndarray
    closed: np.ndarray
    hand: np.ndarray

    @cached_property
    def parts(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The bones ``(F, 3, 3)`` split for Rodrigues' formula: the part along the axis,
        the part across it, and the axis crossed with the bone."""
        axis = self.axis[:, None]
        along = axis * (self.segments * axis).sum(-1, keepdims=True)
        return along, self.segments - along, np.cross(axis, self.segments)


def finger_rig(skeleton: Skeleton) -> FingerRig:
    """The fingers of a skeleton with the avatar rig's finger bones
    (:func:`~synthesis.avatargo.hands.has_fingers`), from its rest pose."""
    rest = skeleton.rest_positions()
    joints, base, segments, axis, hand = [], [], [], [], []
    for h, side in enumerate("LR"):
        wrist = rest[skeleton.index(f"Bip01 {side} Hand")]
        for f in range(5):
            chain = skeleton.indices([finger_joint(side, f, s) for s in ("", "1", "2", "Nub")])
            points = rest[chain] - wrist
            direction = points[-1] - points[0]
            flex = np.cross(direction, PALM_NORMAL)
            joints.append(chain[:3])
            base.append(points[0])
            segments.append(np.diff(points, axis=0))
            axis.append(flex / np.linalg.norm(flex))
            hand.append(h)
    return FingerRig(
        np.array(joints),
        np.array(base),
        np.array(segments),
        np.array(axis),
        np.radians(np.tile(CLOSED_DEG, (2, 1))),
        np.array(hand),
    )


def finger_points(rig: FingerRig, t: np.ndarray) -> np.ndarray:
    """``(..., F, 3, 3)`` hand-frame positions of the points each finger's joints move (the
    second and third joints and the tip) for parameters ``t (..., F, 3)``.

    Every joint of a finger turns about the same axis ``a``, so a bone ``v`` turned by the
    sum of the angles above it is ``v_par + v_perp cos + (a x v) sin`` (Rodrigues) with the
    three parts precomputed (:attr:`FingerRig.parts`): no cross product on the hot path."""
    angle = np.cumsum(t * rig.closed, axis=-1)[..., None]  # each joint turns the bones below
    along, across, turned = rig.parts
    bones = along + across * np.cos(angle) + turned * np.sin(angle)
    return rig.base[:, None] + np.cumsum(bones, axis=-2)


def capsule_sdf(p: np.ndarray, s: np.ndarray, e: np.ndarray, r: float) -> np.ndarray:
    """Eq. 5: signed distance ``(...)`` of points ``p (..., 3)`` to the capsule from ``s`` to
    ``e`` (broadcasting ``(..., 3)``) of radius ``r`` (negative inside)."""
    v1, v2 = p - s, e - s
    h = np.clip((v1 * v2).sum(-1, keepdims=True) / (v2 * v2).sum(-1, keepdims=True), 0.0, 1.0)
    gap = v1 - v2 * h
    return np.sqrt((gap * gap).sum(-1)) - r


class FingerIK:
    """Gradient-descent finger IK of both hands on their controllers' handles.

    Args:
        skeleton: a skeleton with the avatar rig's finger bones.
        grip: where the controllers sit in the hand frames.
        thumb_button: optional ``(2, 3)`` button point per hand (hand frame) the thumb tips
            also move towards (§3.4's second goal).
        iterations_per_tick: gradient steps per frame after the first solve.
    """

    def __init__(
        self,
        skeleton: Skeleton,
        grip: Grip,
        thumb_button: np.ndarray | None = None,
        iterations_per_tick: int = 2,
    ):
        self.rig = finger_rig(skeleton)
        ends = grip.handle[self.rig.hand]  # (F, 2, 3)
        self.start, self.end = ends[:, None, 0], ends[:, None, 1]  # (F, 1, 3)
        self.thumb_button = thumb_button
        self.iterations_per_tick = int(iterations_per_tick)
        self._first = self._first_solve()
        self.reset()

    def _first_solve(self) -> tuple[np.ndarray, np.ndarray, bool]:
        """``t (F, 3)``, the step sizes ``(F,)`` and whether converged after the first frame's
        solve: :data:`SETTLE_ITERATIONS` steps from the open hand. The handles and the thumb
        goal are fixed in the hand frames, so this is the same every session: solved once
        here, at calibration, not in the first 90 Hz tick (~25 ms, two dropped frames)."""
        self.reset()
        self._eta = np.maximum(self._eta, ETA_FLOOR)
        self.iterate(SETTLE_ITERATIONS)
        return self.t, self._eta, self._converged

    @property
    def t(self) -> np.ndarray:
        """``(F, 3)`` the current open-to-closed parameters."""
        return self._t

    @t.setter
    def t(self, value: np.ndarray) -> None:
        self._t = value
        self._rotations: np.ndarray | None = None

    def rotations(self) -> np.ndarray:
        """``(F, 3, 4)`` :meth:`local_rotations` of the current ``t``, computed once per ``t``
        (a settled hand holds its pose tick after tick)."""
        if self._rotations is None:
            self._rotations = self.local_rotations(self._t)
        return self._rotations

    def reset(self) -> None:
        """Open hands, fresh step sizes."""
        n = self.rig.joints.shape[0]
        self.t = np.zeros((n, 3))
        self._eta = np.full(n, LEARNING_RATE)
        self._settled = False
        self._converged = False

    def sdf(self, t: np.ndarray) -> np.ndarray:
        """``(..., F, 3)`` signed distance of each finger point to its handle."""
        return capsule_sdf(finger_points(self.rig, t), self.start, self.end, CONTROLLER_RADIUS_M)

    def cost(self, t: np.ndarray) -> np.ndarray:
        """Eq. 6 per finger ``(..., F)`` with the penetration penalty (and thumb button)."""
        d = self.sdf(t)
        cost = np.where(d < 0, -PENETRATION_PENALTY * d, d).sum(-1)
        if self.thumb_button is not None:
            tips = finger_points(self.rig, t)[..., ::5, 2, :]  # (..., 2, 3) thumb tips
            cost[..., ::5] += np.linalg.norm(tips - self.thumb_button, axis=-1)
        return cost

    def iterate(self, steps: int) -> np.ndarray:
        """``steps`` gradient steps of eq. 7 from the current ``t``; returns ``t (F, 3)``."""
        h = GRADIENT_STEP
        probe = np.concatenate([np.zeros((1, 3)), h * np.eye(3), -h * np.eye(3)])  # (7, 3)
        for _ in range(steps):
            costs = self.cost(self.t + probe[:, None, :])  # (7, F)
            grad = (costs[1:4] - costs[4:7]).T / (2 * h)  # (F, 3)
            trial = np.clip(self.t - self._eta[:, None] * grad, 0.0, 1.0)
            better = self.cost(trial) < costs[0]
            self.t = np.where(better[:, None], trial, self.t)
            self._converged = not better.any()
            grown = np.minimum(1.5 * self._eta, MAX_LEARNING_RATE)
            self._eta = np.where(better, grown, 0.5 * self._eta)
        return self.t

    def advance(self) -> np.ndarray:
        """One frame's solve (the first settles from the open hand, solved once at
        construction, :meth:`_first_solve`): ``t (F, 3)``.

        The handles sit still in the hand frames (:class:`~synthesis.avatargo.hands.Grip`)
        and the thumb goal is fixed, so the problem is the same every frame: once a round of
        steps improves no finger, the pose is held without probing (the 1 ms aim)."""
        if not self._settled:  # the first frame: the solve from the open hand, stored
            self._settled = True
            t, eta, self._converged = self._first
            self.t, self._eta = t.copy(), eta.copy()
            return self.t
        if self._converged:
            return self.t
        # A finger whose step size collapsed has converged; let it probe again each frame.
        self._eta = np.maximum(self._eta, ETA_FLOOR)
        return self.iterate(self.iterations_per_tick)

    def local_rotations(self, t: np.ndarray) -> np.ndarray:
        """``(..., F, 3, 4)`` wxyz local rotations of the finger joints for ``t (..., F, 3)``
        (rest frames are the hand's, so each joint turns about the finger's axis)."""
        axis = np.broadcast_to(self.rig.axis[:, None], (*t.shape, 3))
        return quat.from_axis_angle(axis, t * self.rig.closed)
