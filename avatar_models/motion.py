"""``Motion``: a skeleton animated over time, with vectorised forward kinematics.

Shapes: ``T`` frames, ``J`` joints. ``root_pos (T, 3)`` is the world position of the root
joint (metres, Z up); ``local_rot (T, J, 4)`` holds each joint's rotation relative to its
parent, wxyz. Global joint ``j``: ``R_j = R_parent * L_j``, ``p_j = p_parent + R_parent offset_j``.
Every operation returns a new ``Motion``; arrays are never modified in place.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.skeleton import Skeleton

# Frame rates a motion may have (frames per second): mocap runs at 30-480 Hz, a 1 kHz system
# is the fastest one records BVH from; anything outside is a wrong Frame Time or --fps.
FPS_RANGE = (1.0, 1000.0)

# Reflection across the sagittal (XZ) plane: a character's left is +Y.
_MIRROR = np.diag([1.0, -1.0, 1.0])


def check_fps(fps: float, what: str = "fps") -> None:
    """A :class:`MotionValueError` unless ``fps`` is in :data:`FPS_RANGE`."""
    lo, hi = FPS_RANGE
    if not (isinstance(fps, int | float | np.number) and np.isfinite(fps) and lo <= fps <= hi):
        raise MotionValueError(f"{what} must be {lo:g}-{hi:g} frames per second, got {fps!r}")


def _depth_levels(parents: np.ndarray, needed: np.ndarray) -> list[np.ndarray]:
    """The ``needed (J,)`` joints grouped by tree depth (root excluded), for level-parallel
    FK."""
    depth = np.zeros(len(parents), dtype=np.int64)
    for j in range(1, len(parents)):
        depth[j] = depth[parents[j]] + 1
    levels = range(1, int(depth.max(initial=0)) + 1)
    return [level for d in levels if (level := np.flatnonzero((depth == d) & needed)).size]


def forward_kinematics(
    skeleton: Skeleton,
    root_pos: np.ndarray,
    local: np.ndarray,
    joints: Sequence[int] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Global positions ``(T, J, 3)`` and rotations ``(T, J, 3, 3)`` from ``root_pos (T, 3)``
    and local rotation matrices ``local (T, J, 3, 3)``.

    Joints at the same tree depth are composed together, so the Python loop runs over depth
    levels (about 10), not frames or joints. ``joints`` limits the work to those joints and
    their ancestors (the others are left undefined): a caller that needs a few joints of a
    matrix pose (the generator's IK, its centre of mass) skips the rest and the round trip
    through quaternions.
    """
    parents = skeleton.parents
    needed = np.zeros(skeleton.n_joints, dtype=bool)
    if joints is None:
        needed[:] = True
    for j in () if joints is None else joints:
        while j >= 0 and not needed[j]:
            needed[j] = True
            j = parents[j]
    glob = np.empty_like(local)
    pos = np.empty((local.shape[0], skeleton.n_joints, 3))
    glob[:, 0] = local[:, 0]
    pos[:, 0] = root_pos
    for level in _depth_levels(parents, needed):
        par = parents[level]
        glob[:, level] = glob[:, par] @ local[:, level]
        pos[:, level] = pos[:, par] + np.einsum(
            "tjab,jb->tja", glob[:, par], skeleton.offsets[level]
        )
    return pos, glob


@dataclass(frozen=True, eq=False)
class Motion:
    """A motion clip. See the module docstring for shapes and conventions.

    Attributes:
        skeleton: the rig.
        fps: frames per second (> 0).
        root_pos: ``(T, 3)`` world position of the root joint.
        local_rot: ``(T, J, 4)`` unit quaternions, wxyz.
        meta: free-form provenance (source path, activity, subject, seed, ...).
    """

    skeleton: Skeleton
    fps: float
    root_pos: np.ndarray
    local_rot: np.ndarray
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        root = np.asarray(self.root_pos, dtype=float)
        rot = np.asarray(self.local_rot, dtype=float)
        nj = self.skeleton.n_joints
        check_fps(self.fps)
        if rot.ndim != 3 or rot.shape[1:] != (nj, 4):
            raise MotionValueError(f"local_rot must be (T, {nj}, 4), got {rot.shape}")
        if root.shape != (rot.shape[0], 3):
            raise MotionValueError(f"root_pos must be ({rot.shape[0]}, 3), got {root.shape}")
        if rot.shape[0] == 0:
            raise MotionValueError("a motion needs at least one frame")
        if not (np.all(np.isfinite(root)) and np.all(np.isfinite(rot))):
            bad = np.flatnonzero(~(np.isfinite(root).all(1) & np.isfinite(rot).all((1, 2))))
            raise MotionValueError(f"motion has NaN/inf in {bad.size} frames (first: {bad[0]})")
        norms = np.linalg.norm(rot, axis=-1)
        if np.any(norms < 1e-9):
            raise MotionValueError("local_rot contains zero quaternions")
        object.__setattr__(self, "root_pos", root)
        object.__setattr__(self, "local_rot", rot / norms[..., None])
        object.__setattr__(self, "fps", float(self.fps))
        object.__setattr__(self, "_fk", None)

    # -- basic properties -----------------------------------------------------------------
    @property
    def n_frames(self) -> int:
        return self.local_rot.shape[0]

    @property
    def duration_s(self) -> float:
        """Time from the first to the last frame."""
        return (self.n_frames - 1) / self.fps

    @property
    def times(self) -> np.ndarray:
        """``(T,)`` frame times in seconds from 0."""
        return np.arange(self.n_frames) / self.fps

    def replace(self, **changes: Any) -> Motion:
        kw = dict(
            skeleton=self.skeleton,
            fps=self.fps,
            root_pos=self.root_pos,
            local_rot=self.local_rot,
            meta=dict(self.meta),
        )
        kw.update(changes)
        return Motion(**kw)

    # -- forward kinematics ---------------------------------------------------------------
    def fk(self) -> tuple[np.ndarray, np.ndarray]:
        """Global positions ``(T, J, 3)`` and rotation matrices ``(T, J, 3, 3)``, cached
        (:func:`forward_kinematics`)."""
        if self._fk is None:  # type: ignore[attr-defined]
            local = quat.to_matrix(self.local_rot)
            object.__setattr__(self, "_fk", forward_kinematics(self.skeleton, self.root_pos, local))
        return self._fk  # type: ignore[attr-defined]

    def global_positions(self) -> np.ndarray:
        """``(T, J, 3)`` world joint positions."""
        return self.fk()[0]

    def global_rotations(self) -> np.ndarray:
        """``(T, J, 4)`` world joint rotations, wxyz."""
        return quat.from_matrix(self.fk()[1])

    def positions_of(self, names: Sequence[str]) -> np.ndarray:
        """``(T, len(names), 3)`` world positions of the named joints."""
        return self.global_positions()[:, self.skeleton.indices(list(names))]

    def velocities(self) -> np.ndarray:
        """``(T, J, 3)`` joint velocities (m/s) by central differences."""
        pos = self.global_positions()
        if self.n_frames < 2:
            return np.zeros_like(pos)
        return np.gradient(pos, 1.0 / self.fps, axis=0)

    def relative_to(self, joint: str, heading: bool = False) -> np.ndarray:
        """``(T, J, 3)`` joint positions relative to ``joint``.

        With ``heading=True`` they are also rotated about +Z so that the joint's facing
        direction (its +X axis projected to the floor) is +X.
        """
        pos = self.global_positions()
        j = self.skeleton.index(joint)
        rel = pos - pos[:, j : j + 1]
        if heading:
            fwd = self.fk()[1][:, j, :, 0]
            yaw = np.arctan2(fwd[:, 1], fwd[:, 0])
            undo = Rotation.from_euler("z", -yaw[:, None]).as_matrix()
            rel = np.einsum("tab,tjb->tja", undo, rel)
        return rel

    def root_relative(self, heading: bool = False) -> np.ndarray:
        """``(T, J, 3)`` positions relative to the root joint."""
        return self.relative_to(self.skeleton.names[0], heading)

    # -- time -----------------------------------------------------------------------------
    def __getitem__(self, frames: slice | np.ndarray | list[int]) -> Motion:
        """Frame selection (a slice or index array). A slice step scales fps down."""
        if isinstance(frames, slice):
            step = frames.step or 1
            if step <= 0:
                raise MotionValueError("frame slices must step forward")
            idx = np.arange(self.n_frames)[frames]
            fps = self.fps / step
        else:
            idx = np.asarray(frames, dtype=np.int64)
            fps = self.fps
        if idx.size == 0:
            raise MotionValueError(f"frame selection {frames!r} is empty ({self.n_frames} frames)")
        return self.replace(fps=fps, root_pos=self.root_pos[idx], local_rot=self.local_rot[idx])

    def sample(self, times: np.ndarray) -> Motion:
        """Motion evaluated at ``times (N,)`` seconds (clamped to the clip), at this fps.

        Root translation is interpolated linearly, rotations by slerp along the shortest
        arc (:func:`avatar_models.quat.power`), all joints at once.
        """
        times = np.clip(np.asarray(times, dtype=float), 0.0, self.duration_s)
        if self.n_frames == 1:
            n = times.size
            return self.replace(
                root_pos=np.repeat(self.root_pos, n, 0), local_rot=np.repeat(self.local_rot, n, 0)
            )
        t = self.times
        root = np.stack([np.interp(times, t, self.root_pos[:, k]) for k in range(3)], axis=1)
        key = np.clip(np.searchsorted(t, times, side="right") - 1, 0, t.size - 2)  # (N,)
        alpha = (times - t[key]) / (t[key + 1] - t[key])  # (N,) in [0, 1]
        start, end = self.local_rot[key], self.local_rot[key + 1]  # (N, J, 4)
        step = quat.mul(quat.conj(start), end)
        step /= np.linalg.norm(step, axis=-1, keepdims=True)
        rot = quat.mul(start, quat.power(step, alpha[:, None]))
        return self.replace(root_pos=root, local_rot=rot)

    def resample(self, fps: float) -> Motion:
        """Same clip at ``fps`` frames per second (the duration is kept, rounded down)."""
        check_fps(fps, "target fps")
        n = int(np.floor(self.duration_s * fps + 1e-9)) + 1
        return self.sample(np.arange(n) / fps).replace(fps=fps)

    def retime(self, speed: float) -> Motion:
        """Play ``speed`` times faster (``speed < 1`` slows down), keeping fps."""
        if not (np.isfinite(speed) and speed > 0):
            raise MotionValueError(f"speed factor must be positive, got {speed!r}")
        n = int(np.floor(self.duration_s / speed * self.fps + 1e-9)) + 1
        return self.sample(np.arange(n) / self.fps * speed)

    @staticmethod
    def concatenate(motions: Sequence[Motion], continue_root: bool = True) -> Motion:
        """Clips one after another. Skeletons (topology) and fps must agree.

        With ``continue_root``, each clip is shifted horizontally so that it starts where the
        previous one ended (heights are kept).
        """
        if not motions:
            raise MotionValueError("nothing to concatenate")
        first = motions[0]
        roots, rots = [first.root_pos], [first.local_rot]
        for m in motions[1:]:
            if not m.skeleton.same_topology(first.skeleton):
                raise MotionValueError("cannot concatenate motions on different skeletons")
            if abs(m.fps - first.fps) > 1e-9:
                raise MotionValueError(f"fps differ ({first.fps} vs {m.fps}); resample first")
            root = m.root_pos.copy()
            if continue_root:
                shift = roots[-1][-1] - root[0]
                shift[2] = 0.0
                root = root + shift
            roots.append(root)
            rots.append(m.local_rot)
        return first.replace(root_pos=np.concatenate(roots), local_rot=np.concatenate(rots))

    # -- space ----------------------------------------------------------------------------
    def mirror(self) -> Motion:
        """Left/right mirror image across the XZ plane, left and right joints swapped.

        Exact: the result's global positions are the reflected originals (``y -> -y``) with
        left and right joint labels exchanged, also for asymmetric skeletons.
        """
        sk = self.skeleton
        m = sk.mirror_map()
        offsets = sk.offsets[m] @ _MIRROR
        # Conjugating a rotation by the reflection diag(1,-1,1) negates its x and z parts.
        rot = self.local_rot[:, m] * np.array([1.0, -1.0, 1.0, -1.0])
        return self.replace(
            skeleton=sk.with_offsets(offsets),
            root_pos=self.root_pos @ _MIRROR,
            local_rot=rot,
        )

    def translated(self, delta: np.ndarray) -> Motion:
        return self.replace(root_pos=self.root_pos + np.asarray(delta, dtype=float))

    def rotated_about_z(self, yaw: float, carrier: int = 0) -> Motion:
        """The whole motion turned by ``yaw`` radians about the world Z axis through the origin.

        ``carrier``: the joint whose local rotation takes the turn (the root by default).
        Another joint (the hips below a static reference root, as Bandai's ``joint_Root``)
        turns itself and every joint below it exactly as the root would, while the joints
        above it keep their rotations and are only moved along: what matters where local
        rotations of several motions are blended, whose heading must sit in one joint.
        """
        r = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(yaw))
        rot = self.local_rot.copy()
        if carrier == 0:
            rot[:, 0] = quat.mul(r, rot[:, 0])
            return self.replace(root_pos=quat.rotate(r, self.root_pos), local_rot=rot)
        positions, matrices = self.fk()
        above = quat.from_matrix(matrices[:, self.skeleton.parents[carrier]])
        # The carrier's global rotation G becomes r G: its local one A^-1 r A times its own.
        rot[:, carrier] = quat.mul(quat.mul(quat.conj(above), quat.mul(r, above)), rot[:, carrier])
        at = positions[:, carrier]
        return self.replace(root_pos=self.root_pos + quat.rotate(r, at) - at, local_rot=rot)

    def __repr__(self) -> str:
        return (
            f"Motion(skeleton={self.skeleton.name or self.skeleton.n_joints!r}, "
            f"frames={self.n_frames}, fps={self.fps:g})"
        )
