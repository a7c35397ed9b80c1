"""``CoolMoves``: full-body accentuation from a headset and two hand controllers (§3.1).

Per 90 Hz sample: the last 100 ms of each hand, head-relative, is matched in the database
(one KD-tree per hand, :mod:`.knn`); every match is turned about the vertical to fit the
input (:mod:`.alignment`); the matched poses are blended, arms from their own hand
(:mod:`.blend`); the result is smoothed by an EWMA weighted by the global match weight
(:mod:`.smoothing`); joint angles are thresholded (:mod:`.limits`); bones are scaled to the
user's height and the body is placed so that its headset point is the input headset's.

Order of the last steps: the paper scales and translates before thresholding; we threshold
first, so that the headset point of the final pose is exactly the tracked one.

Invalid input: a hand is matched only when its whole window (and the headset) was tracked;
a tracked side always has matches (:mod:`.knn`); an untracked side has none and holds its
limb (EWMA weight 0), with neither side tracked the whole pose
holds, and the translation holds the last tracked headset position. Late or repeated
timestamps are ignored by ``step``; ``run`` repairs and re-clocks the stream first.

The method is written once, over a batch of frames (:meth:`CoolMoves.advance`): ``step`` is a
batch of one, ``run`` the whole stream (:mod:`synthesis.base`). Its state between calls: the
last window of hand samples, the smoothed pose, the last headset position and bone scale,
and the foot-contact state.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import Skeleton
from avatarsim.avatar_models.body.description import UPRIGHT_RATIO
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams.vr import nominal_attachment
from avatarsim.synthesis.base import FrameBatch, Poses, SynthesisError, Synthesizer
from avatarsim.synthesis.coolmoves.alignment import alignment_yaw, turn_about_vertical
from avatarsim.synthesis.coolmoves.blend import (
    blend_rotations,
    global_match_weight,
    group_shares,
    group_weights,
    joint_groups,
)
from avatarsim.synthesis.coolmoves.database import Database
from avatarsim.synthesis.coolmoves.features import RATE_HZ, search_vectors, sliding_windows
from avatarsim.synthesis.coolmoves.foot_contact import FootContact
from avatarsim.synthesis.coolmoves.knn import K_NEIGHBOURS, MAX_DISTANCE, BothHandsKNN, PerHand
from avatarsim.synthesis.coolmoves.limits import JointLimits
from avatarsim.synthesis.coolmoves.smoothing import ewma
from avatarsim.synthesis.two_bone import chain_fk
from avatarsim.synthesis.two_bone import solve as two_bone

EYE_HEIGHT_FRAC = 0.936
ANKLE_HEIGHT_FRAC = 0.039
"""Eye and ankle heights over stature (Drillis & Contini 1966, the segment-length
proportions in Winter, *Biomechanics and Motor Control of Human Movement*, Fig. 4.1)."""


@dataclass(frozen=True)
class Options:
    """Switches of the method; the defaults are the paper's pipeline (its ablation turns off
    alignment and smoothing).

    Attributes:
        k: matches per hand. max_distance: KD-tree neighbourhood threshold.
        align: rotation alignment (§3.1.4). align_about_centroid: the paper's printed
            alignment equation (clouds turned about their centroids) instead of about the
            head (:mod:`.alignment` says why the head is the default). align_own_hand: each
            hand's matches turned to fit that hand's window only (the matched feature vector,
            §3.1.4's ``s``) instead of both hands' windows of the matched database window.
        smooth: EWMA smoothing. clamp: joint limits.
        matcher: ``"knn"`` (the paper's method) or ``"gmm"`` (the slower mixture variant).
        arm_ik: beyond the paper, the share (0..1) by which each arm is bent with two-bone IK
            (:mod:`synthesis.two_bone`) so that its controller point reaches the tracked controller;
            applied where that hand is tracked, after the joint limits, which are applied
            again. 0 (the default) is the paper's output: hands from the blended database
            poses only; the registered method ``coolmoves+arm-ik`` sets 1
            (:mod:`synthesis.methods`).
        foot_contact: beyond the paper, pin stance feet to the floor (:mod:`.foot_contact`).
    """

    k: int = K_NEIGHBOURS
    max_distance: float = MAX_DISTANCE
    align: bool = True
    align_about_centroid: bool = False
    align_own_hand: bool = False
    smooth: bool = True
    clamp: bool = True
    matcher: str = "knn"
    arm_ik: float = 0.0
    foot_contact: bool = False


_LIMBS = {
    side + root: tuple(side + part for part in parts)
    for side in ("l_", "r_")
    for root, parts in (
        ("shoulder", ("shoulder", "elbow", "wrist")),
        ("hip", ("hip", "knee", "ankle")),
    )
}
"""body17 upper, middle and end joints of each limb a driver can govern."""


class _Limb:
    """Two-bone limbs (upper, middle, end joint) and the device point on each end joint.

    One limb, or ``S`` limbs whose root-to-end chains have one length, solved together
    (``joints (S, 3)``, device offsets ``(S, 3)``): both arms in one pass of numpy calls.
    """

    def __init__(self, skeleton: Skeleton, joints, device_offset):
        self.offsets = skeleton.offsets
        self.joints = np.asarray(joints)
        self.chain = np.array([skeleton.chain(j) for j in self.joints.reshape(-1, 3)[:, -1]])
        self.chain = self.chain.reshape(*self.joints.shape[:-1], -1)
        self.device_offset = np.asarray(device_offset, float)

    @classmethod
    def for_driver(cls, skeleton: Skeleton, limb: str, device: str) -> _Limb | None:
        """The limb ``limb`` (a body17 name) driven by ``device``, if the device sits on its
        end joint (else None: no IK for that driver)."""
        rig = identify_rig(skeleton)
        attachment = nominal_attachment(device, skeleton)
        names = _LIMBS.get(limb)
        if names is None or attachment.joint != names[-1]:
            return None
        joints = tuple(skeleton.index(rig.body17[n]) for n in names)
        return cls(skeleton, joints, attachment.position)

    @classmethod
    def together(cls, skeleton: Skeleton, limbs: list[_Limb | None]) -> list[tuple[list, _Limb]]:
        """``[(sides, limb)]``: the given single limbs as one multi-limb where their chains
        have one length, else one by one; ``sides`` index ``limbs`` (None entries skipped)."""
        present = [(side, limb) for side, limb in enumerate(limbs) if limb is not None]
        if len(present) > 1 and len({limb.chain.shape for _, limb in present}) == 1:
            joints = np.stack([limb.joints for _, limb in present])
            offsets = np.stack([limb.device_offset for _, limb in present])
            return [([side for side, _ in present], cls(skeleton, joints, offsets))]
        return [([side], limb) for side, limb in present]

    def reach(
        self,
        rotations: np.ndarray,
        root: np.ndarray,
        scale: np.ndarray,
        device: np.ndarray,
        weight: np.ndarray,
    ) -> np.ndarray:
        """``rotations (B, J, 4)`` with the device point moved ``weight (B, [S])`` of the way
        to ``device (B, [S,] 3)`` (world), by moving the end joint as much (its rotation is
        kept)."""
        globs, positions = chain_fk(rotations, root, self.offsets, scale, self.chain)
        end_pos, end_rot = positions[..., -1, :], globs[..., -1, :, :]
        point = end_pos + (end_rot @ self.device_offset[..., None])[..., 0]
        target = end_pos + weight[..., None] * (device - point)
        return two_bone(
            rotations, globs[..., -4:, :, :], positions[..., -4:, :], self.joints, target
        )


class CoolMoves(Synthesizer):
    """The CoolMoves synthesiser on a built :class:`Database`.

    Args:
        database: stylised poses and their hand windows.
        user_height_m: the user's standing height; None estimates it from the first tracked
            headset height (assuming the user stands then).
        options: method switches.
    """

    name = "coolmoves"

    def __init__(
        self,
        database: Database,
        user_height_m: float | None = None,
        options: Options | None = None,
    ):
        self.database = database
        self.devices = tuple(database.drivers.devices)
        self.options = options or Options()
        self.user_height_m = user_height_m
        self._matcher = self._make_matcher()
        self._groups = joint_groups(database.limb_masks)
        self._match_side = np.repeat(np.eye(2), self.options.k, axis=0)  # (2k, 2) one-hot
        self._group_shares = group_shares(self._groups)
        self._limits = JointLimits(database.skeleton, widen_to=database.poses)
        ref = database.skeleton
        rig = identify_rig(ref)
        self._head_chain = ref.chain(ref.index(rig.body17["head"]))
        self._eye = nominal_attachment(database.drivers.head, ref).position
        rest = ref.rest_positions()
        head_rest = rest[self._head_chain[-1]] + self._eye
        self._ref_height = standing_height(ref)
        self._ref_hmd_height = float(head_rest[2] - rest[:, 2].min())
        # The body's test of a standing rest pose, on the headset height over stature.
        upright = self._ref_hmd_height >= UPRIGHT_RATIO * self._ref_height
        if not upright:
            # A rest pose that is not upright (Bandai's): eye height from stature instead.
            self._ref_hmd_height = EYE_HEIGHT_FRAC * self._ref_height
        drv = database.drivers
        arms = [
            _Limb.for_driver(ref, limb, device)
            for limb, device in ((drv.left_limb, drv.left), (drv.right_limb, drv.right))
        ]
        self._arms = _Limb.together(ref, arms)
        legs = [[ref.index(rig.body17[f"{s}_{p}"]) for p in ("hip", "knee", "ankle")] for s in "lr"]
        self._legs = [_Limb(ref, tuple(joints), np.zeros(3)) for joints in legs]
        arm_joints = {int(j) for _, arm in self._arms for j in arm.joints.ravel()}
        self._arm_limits = JointLimits(ref, widen_to=database.poses, only=arm_joints)
        ankle = ref.index(rig.body17["l_ankle"])
        self._ankle_standing = (
            float(rest[ankle, 2] - rest[:, 2].min())
            if upright
            else ANKLE_HEIGHT_FRAC * self._ref_height
        )
        self._leg_length = float(np.linalg.norm(ref.offsets[list(legs[0][1:])], axis=-1).sum())
        self.reset()

    def _make_matcher(self) -> BothHandsKNN | PerHand:
        opts, db = self.options, self.database
        if opts.matcher == "knn":
            return BothHandsKNN(db.search, opts.k, opts.max_distance)
        if opts.matcher == "gmm":
            from avatarsim.synthesis.coolmoves.gmm import GaussianMixtureMatcher

            return PerHand(
                GaussianMixtureMatcher(db.search[s], opts.k, opts.max_distance) for s in (0, 1)
            )
        raise SynthesisError(f"unknown matcher {opts.matcher!r}; use 'knn' or 'gmm'")

    # -- state ----------------------------------------------------------------------------
    def reset_state(self) -> None:
        n = self.database.window_samples
        self._window = np.full((n, 2, 3), np.nan)  # the last n head-relative hand samples
        self._tracked = np.zeros((n, 2), bool)
        self._state = self.database.mean_pose.copy()  # the smoothed pose (J, 4)
        self._initialised = np.zeros(self.database.skeleton.n_joints, bool)
        self._hmd: np.ndarray | None = None  # the last tracked headset position
        self._scale: float | None = self._scale_for(self.user_height_m)
        self._feet = FootContact(RATE_HZ)

    @property
    def skeleton(self) -> Skeleton:
        """The output rig: the database rig scaled to the user's height (once known)."""
        return self.database.skeleton.scaled(self._scale or 1.0)

    def settings(self) -> dict:
        return {"options": vars(self.options)}

    @property
    def standing_ankle_height(self) -> float:
        """Height (m) of the output's ankles above the floor when standing (foot contact)."""
        return (self._scale or 1.0) * self._ankle_standing

    def _scale_for(self, height_m: float | None) -> float | None:
        return None if height_m is None else float(height_m) / self._ref_height

    def _scale_from_hmd(self, hmd_z: float) -> float:
        """Bone scale from a standing headset height (the reference rig's HMD height ratio)."""
        return self._scale_for(hmd_z * self._ref_height / self._ref_hmd_height)

    # -- the method, on a batch of windows ------------------------------------------------
    def match(self, windows: np.ndarray, tracked: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Blended poses for ``B`` input windows, before smoothing.

        Args:
            windows: ``(B, n, 2, 3)`` head-relative left/right driver positions.
            tracked: ``(B, 2)`` bool, whether each side's window is usable.
        Returns:
            rotations ``(B, J, 4)`` (zero where a joint got no match) and the EWMA weight
            of each joint ``(B, J)``: the global match weight where it got matches, else 0.
        """
        db, opts = self.database, self.options
        queries = search_vectors(windows.transpose(0, 2, 1, 3))  # (B, 2, F)
        dist, idx, match_weights = self._matcher.query(queries, tracked)
        weights, confidence = group_weights(dist, opts.max_distance, match_weights)
        entries = np.concatenate([idx[0], idx[1]], axis=1)  # (B, 2k)
        safe = np.maximum(entries, 0)
        rotations = db.poses[db.entry_pose[safe]]  # (B, 2k, J, 4), a copy (fancy index)
        if opts.align:
            sides = tracked[:, None, :] * self._match_side if opts.align_own_hand else tracked
            yaw = alignment_yaw(windows, db.windows[safe], sides, opts.align_about_centroid)
            rotations[:, :, 0] = turn_about_vertical(rotations[:, :, 0], yaw)
        blended = blend_rotations(rotations, weights[:, self._groups, :])  # (B, J, 4)
        matched = (np.add.reduce(weights, axis=-1) > 0)[:, self._groups]  # (B, J)
        strength = global_match_weight(confidence, self._group_shares) if opts.smooth else 1.0
        return blended, np.where(matched, np.asarray(strength).reshape(-1, 1), 0.0)

    def _place(self, rotations: np.ndarray, hmd: np.ndarray, scale: np.ndarray) -> np.ndarray:
        """Root positions ``(B, 3)`` putting each pose's headset point at ``hmd (B, 3)``.

        Forward kinematics along the root-to-head chain only, on the rig scaled by ``scale``.
        """
        origin = np.zeros((rotations.shape[0], 3))
        globs, positions = chain_fk(
            rotations, origin, self.database.skeleton.offsets, scale, self._head_chain
        )
        return hmd - (positions[:, -1] + globs[:, -1] @ self._eye)

    def _finish(
        self,
        smoothed: np.ndarray,
        hmd: np.ndarray,
        scale: np.ndarray,
        hands: np.ndarray,
        hands_ok: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Final rotations ``(B, J, 4)`` and roots ``(B, 3)``: limits, placement, arm IK.

        ``hands (B, 2, 3)`` are the world driver positions, usable where ``hands_ok (B, 2)``
        (elsewhere any value, NaN included: only arm IK reads them).
        """
        clamp = self._limits.clamp if self.options.clamp else (lambda r: r)
        rotations = clamp(smoothed)
        root = self._place(rotations, hmd, scale)
        if self.options.arm_ik > 0 and hands_ok.any():
            hands = np.where(hands_ok[..., None], hands, 0.0)  # NaN-free: weight 0 there
            for sides, arm in self._arms:
                side = sides if arm.joints.ndim == 2 else sides[0]
                weight = np.where(hands_ok[:, side], self.options.arm_ik, 0.0)
                rotations = arm.reach(rotations, root, scale, hands[:, side], weight)
            # The head chain does not pass through an arm: the placement stays exact.
            if self.options.clamp:
                rotations = self._arm_limits.clamp(rotations)
        if self.options.foot_contact:
            rotations = self._plant_feet(rotations, root, scale)
        return rotations, root

    def _plant_feet(self, rotations: np.ndarray, root: np.ndarray, scale: np.ndarray):
        """``rotations (B, J, 4)`` with stance feet pinned (:mod:`.foot_contact`), frame by
        frame through the contact state machine, then two-bone IK on all frames at once."""
        legs = [chain_fk(rotations, root, leg.offsets, scale, leg.chain)[1] for leg in self._legs]
        ankles = np.stack([p[:, -1] for p in legs], axis=1)  # (B, 2, 3)
        hips = np.stack([p[:, -3] for p in legs], axis=1)
        standing, leg_m = scale * self._ankle_standing, scale * self._leg_length
        targets, fade = np.empty_like(ankles), np.empty(ankles.shape[:2])
        for b in range(ankles.shape[0]):
            targets[b], fade[b] = self._feet.update(ankles[b], hips[b], leg_m[b], standing[b])
        for side, leg in enumerate(self._legs):
            pinned = fade[:, side] > 0
            if pinned.any():
                moved = leg.reach(rotations, root, scale, targets[:, side], np.ones_like(standing))
                rotations = np.where(pinned[:, None, None], moved, rotations)
        return rotations

    def _default_hmd(self) -> np.ndarray:
        return np.array([0.0, 0.0, self._ref_hmd_height])

    # -- the core: a batch of consecutive frames -----------------------------------------
    def advance(self, frames: FrameBatch) -> Poses:
        """Poses for ``B`` consecutive frames; carries the last window, the smoothed pose, the
        headset and the foot contacts from the previous call (``step`` is a batch of one)."""
        n, b = self.database.window_samples, frames.size
        index = self.device_index(frames)  # head, left, right
        drivers = frames.positions[:, index]  # (B, 3, 3)
        ok = frames.usable()[:, index]
        sides_ok = ok[:, 1:] & ok[:, :1]
        rel = np.where(sides_ok[..., None], drivers[:, 1:] - drivers[:, :1], np.nan)
        # The last n - 1 samples before this batch complete its first windows.
        padded_rel = np.concatenate([self._window[1:], rel])
        padded_ok = np.concatenate([self._tracked[1:], sides_ok])
        self._window, self._tracked = padded_rel[-n:], padded_ok[-n:]
        if b == 1:  # one step: its window is the carried one (sliding_windows' single row)
            windows, window_ok = padded_rel[None], padded_ok.all(axis=0)[None]
        else:
            ends = np.arange(n - 1, n - 1 + b)
            windows = sliding_windows(padded_rel, ends, n)  # (B, n, 2, 3)
            window_ok = sliding_windows(padded_ok, ends, n).all(axis=1)  # (B, 2)
        has_window = window_ok.any(axis=1)
        if has_window.all():  # every frame has a window (a tracked stream, or one step)
            blended, weight = self.match(windows, window_ok)
        else:  # frames without any window get no match: zero weight, the state holds
            rows = np.flatnonzero(has_window)
            blended = np.zeros((b, self.database.skeleton.n_joints, 4))
            weight = np.zeros((b, self.database.skeleton.n_joints))
            if rows.size:
                blended[rows], weight[rows] = self.match(windows[rows], window_ok[rows])
        # A joint's first match replaces the initial mean pose outright.
        matched = weight > 0
        if b == 1:  # one step: what the running "or" over the batch's earlier frames gives
            seen_before = self._initialised[None]
        else:
            seen_before = np.logical_or.accumulate(
                np.concatenate([self._initialised[None], matched[:-1]]), axis=0
            )
        self._initialised = seen_before[-1] | matched[-1]
        smoothed = ewma(blended, np.where(seen_before, weight, matched), self._state)
        self._state = smoothed[-1]
        hmd, scale = self._hmd_track(drivers[:, 0], ok[:, 0])
        rotations, root = self._finish(smoothed, hmd, scale, drivers[:, 1:], sides_ok)
        return Poses(root, rotations)

    def _hmd_track(self, hmd: np.ndarray, ok: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Last tracked headset position per frame ``(B, 3)`` (before any: the one carried
        from earlier batches, else the rig's standing headset) and the bone scale ``(B,)``."""
        if ok.size == 1:  # one step: the same numbers without the running maximum over frames
            return self._hmd_step(hmd, bool(ok[0]))
        last = np.maximum.accumulate(np.where(ok, np.arange(ok.size), -1))
        before = self._default_hmd() if self._hmd is None else self._hmd
        held = np.where((last >= 0)[:, None], hmd[np.maximum(last, 0)], before)
        if self._scale is None and ok.any():
            self._scale = self._scale_from_hmd(float(hmd[np.argmax(ok), 2]))
        seen = (last >= 0) | (self._hmd is not None)
        scale = np.where(seen, self._scale or 1.0, 1.0)
        if self.user_height_m is not None:
            scale[:] = self._scale
        if seen[-1]:
            self._hmd = held[-1]
        return held, scale

    def _hmd_step(self, hmd: np.ndarray, ok: bool) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_hmd_track` of one frame ``hmd (1, 3)`` (a step costs a few scalar tests
        where the batch form takes a dozen numpy calls)."""
        if ok:
            held = hmd
            if self._scale is None:
                self._scale = self._scale_from_hmd(float(hmd[0, 2]))
        else:
            held = (self._default_hmd() if self._hmd is None else self._hmd)[None]
        seen = ok or self._hmd is not None
        if self.user_height_m is not None:
            scale = self._scale
        else:
            scale = (self._scale or 1.0) if seen else 1.0
        if seen:
            self._hmd = held[-1]
        return held, np.array([scale], float)
