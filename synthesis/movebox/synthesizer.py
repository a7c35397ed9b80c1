"""``MoveBox``: the Kinect skeleton stream retargeted live onto an avatar (MoveBox §III-A1).

The method reads a Kinect V2 or Azure Kinect skeleton stream (30 Hz), not the VR stream; it
advances on the VR stream's 90 Hz clock (:class:`~synthesis.base.Synthesizer`) and at each
tick uses only the Kinect frames stamped at or before it. Per new Kinect frame:
:class:`~synthesis.movebox.retarget.Retargeting` (q_absolute down the hierarchy, roll,
wrist stabilisation), then :class:`~synthesis.movebox.confidence.ConfidenceFilter`
(NotTracked held, Inferred blended, never-seen at rest); per display tick: the latest
frame, its absolute rotations smoothed (:mod:`.smoothing`), which also carries 30 Hz onto
90 Hz. The paper smooths the rotations only ("the rotations between frames are interpolated
using exponential smoothing", §III-A1), so the root position steps with each Kinect frame;
smoothing it as well (``smooth_root``) goes beyond the paper: it removes the 30 Hz steps
(jerk) at the price of lag, ~5-9 cm behind a runner at 2.6-3.6 m/s
(``tests/measurements/movebox_error_sources.py``).

Shapes: ``B`` ticks, ``N`` Kinect frames, ``K`` Kinect joints, ``J`` avatar joints.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import Motion, Skeleton, quat
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams.kinect import KinectSkeletonStream, TrackingState
from avatarsim.synthesis.base import DEFAULT_RATE_HZ, FrameBatch, Poses, SynthesisError, Synthesizer
from avatarsim.synthesis.movebox.confidence import ConfidenceFilter, bone_states, forward_fill
from avatarsim.synthesis.movebox.mapping import PELVIS, mapping_for
from avatarsim.synthesis.movebox.retarget import ROLLS, Retargeting
from avatarsim.synthesis.movebox.smoothing import (
    TIME_CONSTANT_S,
    ExponentialSmoother,
    absolute,
    relative,
    smoothing_alpha,
)

DEFAULT_ROLL = {"kinect_v2": "rest", "azure_kinect": "sensor"}
"""Roll per sensor, as the paper does it (§IV-B1): V2 has none of its own, so the avatar's
rest roll; Azure's own. ``"hinge"`` (the rest roll turned onto the avatar's elbow and knee
hinge axes, :mod:`.retarget`) goes beyond the paper and is asked for by name."""


def check_stream(kinect: KinectSkeletonStream) -> None:
    """Raise :class:`SynthesisError` for a stream MoveBox cannot use: no frame, frames out of
    order, or no joint ever tracked (the performer was never in view)."""
    if kinect.n_samples == 0:
        raise SynthesisError(f"the {kinect.rig} skeleton stream has no frame")
    if not np.all(np.diff(kinect.timestamps) > 0) or not np.all(np.isfinite(kinect.timestamps)):
        raise SynthesisError(f"the {kinect.rig} skeleton stream's timestamps are not increasing")
    if np.all(kinect.states == TrackingState.NOT_TRACKED):
        raise SynthesisError(
            f"every joint of the {kinect.rig} skeleton stream is NotTracked in all "
            f"{kinect.n_samples} frames: nobody was in the sensor's view and range"
        )


class MoveBox(Synthesizer):
    """Kinect capture onto an avatar rig.

    Args:
        kinect: the skeleton stream (``kinect_v2`` or ``azure_kinect`` rig).
        target: the avatar skeleton to drive (the avatar rig's joints, any proportions).
        roll: ``"hinge"``, ``"rest"``, ``"sensor"`` or ``"auto"`` (:data:`DEFAULT_ROLL`).
        stabilise_wrists: hands follow the forearm (§IV-B2).
        tau_s: smoothing time constant (0: none).
        smooth_root: also smooth the root position (beyond the paper, see above).

    Raises:
        SynthesisError: an unusable stream (:func:`check_stream`), an unknown Kinect rig
            or roll, or a target without the avatar rig's joints.
    """

    name = "movebox"
    devices = ()

    def __init__(
        self,
        kinect: KinectSkeletonStream,
        target: Skeleton,
        roll: str = "auto",
        stabilise_wrists: bool = True,
        tau_s: float = TIME_CONSTANT_S,
        smooth_root: bool = False,
    ) -> None:
        check_stream(kinect)
        mapping = mapping_for(kinect.rig)
        roll = DEFAULT_ROLL[kinect.rig] if roll == "auto" else roll
        if roll not in ROLLS:
            raise SynthesisError(f"roll must be auto or one of {ROLLS}, got {roll!r}")
        if PELVIS not in target or not all(d.joint in target for d in mapping.drives):
            raise SynthesisError(f"MoveBox drives avatar-rig skeletons, not {target!r}")
        self.kinect = kinect
        self.retargeting = Retargeting(
            target,
            mapping,
            load_rig(kinect.rig).skeleton.rest_positions(),
            kinect.joint_names,
            roll,
            stabilise_wrists,
        )
        self.retargeting.check_chains()
        self._sources = self.retargeting.joint_sources()
        self._root_joint = kinect.joint_names.index(mapping.root)
        self.tau_s = float(tau_s)
        self.smooth_root = bool(smooth_root)
        self.reset()

    @property
    def skeleton(self) -> Skeleton:
        return self.retargeting.target

    def settings(self) -> dict:
        return {
            "sensor": self.kinect.rig,
            "roll": self.retargeting.roll,
            "stabilise_wrists": self.retargeting.stabilise_wrists,
            "tau_s": self.tau_s,
            "smooth_root": self.smooth_root,
        }

    def reset_state(self) -> None:
        n_joints = self.skeleton.n_joints
        self._consumed = 0
        self._confidence = ConfidenceFilter.at_rest(n_joints)
        self._last_rot = np.tile(quat.IDENTITY, (1, n_joints, 1))
        self._last_root = self.skeleton.offsets[:1].copy()
        self._smoother = ExponentialSmoother(smoothing_alpha(DEFAULT_RATE_HZ, self.tau_s))

    def kinect_frames(self, start: int, stop: int) -> tuple[np.ndarray, np.ndarray]:
        """``root_pos (N, 3)`` and ``local_rot (N, J, 4)`` of Kinect frames ``start:stop``,
        retargeted and through the tracking-state rules (advances their state)."""
        k = self.kinect
        states = k.states[start:stop]
        # NotTracked joints carry no data (the SDK reports none); zeros keep the algebra
        # finite and the rules below never use what comes out of them.
        positions = np.nan_to_num(k.positions[start:stop])
        orientations = k.orientations[start:stop].copy()
        unusable = ~np.isfinite(orientations).all(-1) | (
            np.linalg.norm(orientations, axis=-1) < 0.5
        )
        orientations[unusable] = quat.IDENTITY
        root, local = self.retargeting(positions, orientations)
        local = self._confidence(local, bone_states(states, self._sources))
        root_seen = states[:, self._root_joint] != TrackingState.NOT_TRACKED
        root = forward_fill(root[:, None], root_seen[:, None], self._last_root)[:, 0]
        return root, local

    def advance(self, frames: FrameBatch) -> Poses:
        ticks = np.asarray(frames.timestamps, float)
        latest = np.nanmax(ticks) if np.isfinite(ticks).any() else -np.inf
        available = int(np.searchsorted(self.kinect.timestamps, latest, side="right"))
        start = self._consumed
        if available > start:
            root, local = self.kinect_frames(start, available)
        else:  # no new Kinect frame: nothing to retarget
            root, local = self._last_root[:0], self._last_rot[:0]
        # Each tick shows the latest Kinect frame at or before it (index -1: none yet).
        seen = np.searchsorted(self.kinect.timestamps, np.nan_to_num(ticks, nan=-np.inf), "right")
        row = np.clip(seen - start, 0, None)  # 0: the last frame before this batch
        roots = np.concatenate([self._last_root, root])[row]
        rots = np.concatenate([self._last_rot, local])[row]
        if local.shape[0]:
            self._consumed = available
            self._last_root, self._last_rot = root[-1:], local[-1:]
        parents = self.skeleton.parents
        world = self._smoother("rot", absolute(rots, parents), True)
        if self.smooth_root:
            roots = self._smoother("root", roots, False)
        return Poses(roots, relative(world, parents))

    def record(self, rate_hz: float = DEFAULT_RATE_HZ) -> Motion:
        """The whole Kinect stream as an animation (MoveBox's recording, §III-B1): a fresh
        session advanced on the 90 Hz display clock from the first Kinect frame to the last,
        without a VR stream, then resampled to ``rate_hz``."""
        stamps = self.kinect.timestamps
        n = int(np.floor((stamps[-1] - stamps[0]) * DEFAULT_RATE_HZ)) + 1
        ticks = stamps[0] + np.arange(n) / DEFAULT_RATE_HZ
        self.reset()
        batch = FrameBatch(ticks, (), np.empty((n, 0, 3)), np.empty((n, 0, 4)), np.empty((n, 0)))
        poses = self.advance(batch)
        meta = {"method": self.name, **self.settings(), "kinect": self.kinect.meta}
        motion = Motion(self.skeleton, DEFAULT_RATE_HZ, poses.root_pos, poses.local_rot, meta=meta)
        return motion if rate_hz == DEFAULT_RATE_HZ else motion.resample(rate_hz)
