"""Kinect joints onto the avatar rig: absolute rotations down the hierarchy (MoveBox §III-A1).

Shapes: ``N`` Kinect frames, ``K`` Kinect joints, ``J`` avatar joints.

Per frame, parents before children, each driven avatar bone (:mod:`.mapping`) gets an
absolute (world) rotation and its local rotation is ``q_local = q_parent_abs^-1 q_abs``, so
that the product down the hierarchy, ``q_abs = prod_{i=root..k} q_i`` (the paper's
q_absolute), gives it back. The absolute rotation of a bone:

1. its roll: either the sensor's orientation of the bone (``roll="sensor"``: the Kinect
   orientation times the rest alignment of the avatar bone to the Kinect bone), or the
   avatar's rest roll (``roll="rest"``: the parent's absolute rotation, i.e. no twist of
   the bone relative to its parent). Kinect V2 has no consistent roll (§IV-B1); MoveBox
   "default[s] the orientation of the joints around themselves to that on the original
   avatar", which is ``"rest"``. ``"hinge"`` (beyond the paper) keeps the rest roll too,
   but also keeps the avatar's rest hinge axes of the elbows and knees: the upper arm and
   thigh take the roll that makes the measured bend of the forearm or calf a flexion of
   the hinge (the roll is then seen, not assumed, wherever the joint is bent).
2. its direction: the smallest rotation that turns the bone (from where its parents put its
   start) towards the Kinect joint it aims at, so the avatar's limbs point where the
   user's do whatever the rig proportions; spine and neck bones aim at their Kinect joints
   scaled to the avatar's torso (:meth:`Retargeting.torso_scaled`), so that an avatar torso
   longer than the user's stays straight instead of folding back towards Kinect joints it
   has passed (:mod:`.mapping`).

Unmapped joints keep their rest rotation relative to their parent. Wrist stabilisation
(§IV-B2: "fix the wrist rotations and set them to match that of the lower arm") leaves the
hands undriven. The pelvis is the rotation that takes the avatar's rest hip vectors to the
Kinect's (spine base to each hip).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from avatarsim.avatar_models import Skeleton, quat
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.movebox.mapping import NECK, PELVIS, PELVIS_TRIAD, BoneDrive, RigMapping

ROLLS = ("hinge", "rest", "sensor")
BEND_FADE = (0.1, 0.3)
"""Sine of the hinge bend over which ``"hinge"`` roll fades in: a nearly straight elbow or
knee has no bend plane (our choice)."""


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Unit quaternions ``q (..., 4)`` applied to ``v (..., 3)`` (or one ``(3,)``), through
    :func:`avatar_models.quat.unit_to_matrix` (no cross products)."""
    return (quat.unit_to_matrix(q) @ np.asarray(v, float)[..., None])[..., 0]


def frame_from_pair(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` orthonormal frames from two vectors ``(..., 3)``: x along ``a + b``,
    z along ``a x b``; the identity where they are (near) parallel or zero (a garbage frame
    must not stop the stream)."""
    x = a + b
    z = quat.cross(a, b)
    nx = np.linalg.norm(x, axis=-1, keepdims=True)
    nz = np.linalg.norm(z, axis=-1, keepdims=True)
    ok = (nx > 1e-9) & (nz > 1e-9)
    x = np.where(ok, x / np.maximum(nx, 1e-12), [1.0, 0.0, 0.0])
    z = np.where(ok, z / np.maximum(nz, 1e-12), [0.0, 0.0, 1.0])
    return np.stack([x, quat.cross(z, x), z], axis=-1)


def twist_angle(q: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """``(...)`` signed angle (radians, in ``(-pi, pi]``) of the twist of ``q (..., 4)`` about
    unit ``axis (..., 3)`` (swing-twist decomposition)."""
    proj = np.sum(q[..., 1:] * axis, axis=-1)
    return 2.0 * np.arctan2(proj, q[..., 0])


@dataclass(frozen=True, eq=False)
class Retargeting:
    """Kinect frames onto an avatar-topology skeleton.

    Attributes:
        target: the avatar skeleton (the avatar rig's joints, any proportions).
        mapping: the Kinect rig's mapping.
        kinect_rest: ``(K, 3)`` the Kinect rig's rest joint positions (for the rest
            alignment of sensor orientations).
        kinect_names: the ``K`` Kinect joint names.
        roll: ``"hinge"``, ``"rest"`` (recover the avatar's rest roll) or ``"sensor"``.
        stabilise_wrists: hands follow the forearm (§IV-B2).
    """

    target: Skeleton
    mapping: RigMapping
    kinect_rest: np.ndarray
    kinect_names: tuple[str, ...]
    roll: str = "hinge"
    stabilise_wrists: bool = True

    def drives(self) -> list[BoneDrive]:
        skip = self.mapping.hands if self.stabilise_wrists else ()
        return [d for d in self.mapping.drives if d.joint not in skip]

    def kinect_index(self, name: str) -> int:
        return self.kinect_names.index(name)

    def rest_alignment(self, drive: BoneDrive) -> np.ndarray:
        """``(4,)`` rotation taking the avatar bone's rest direction to the Kinect rest bone
        its orientation turns (so that the Kinect orientation applies to the avatar bone)."""
        a, b = (self.kinect_index(n) for n in drive.orient_rest)
        return quat.shortest_arc(
            self.target.offsets[self.target.index(drive.child)],
            self.kinect_rest[b] - self.kinect_rest[a],
        )

    @cached_property
    def torso_m(self) -> float:
        """The avatar's rest pelvis-to-neck distance."""
        rest = self.target.rest_positions()
        return float(
            np.linalg.norm(rest[self.target.index(NECK)] - rest[self.target.index(PELVIS)])
        )

    def torso_scaled(self, positions: np.ndarray) -> np.ndarray:
        """``(N, K, 3)`` Kinect ``positions (N, K, 3)`` scaled about the Kinect root, per
        frame, so that root-to-neck is the avatar's :attr:`torso_m`: where the spine and neck
        bones aim (the user's torso directions on the avatar's torso length)."""
        root = positions[:, [self.kinect_index(self.mapping.root)]]
        neck = positions[:, [self.kinect_index(self.mapping.neck)]]
        user = np.linalg.norm(neck - root, axis=-1, keepdims=True)
        return root + (positions - root) * (self.torso_m / np.maximum(user, 1e-6))

    def check_chains(self) -> None:
        """Every driven joint's ancestors are driven or the root (what ``__call__`` needs).

        Raises:
            SynthesisError: a mapping that leaves a gap in a driven chain.
        """
        sk = self.target
        driven = {sk.index(d.joint) for d in self.drives()} | {sk.index(PELVIS), 0}
        gaps = [sk.names[j] for j in driven if sk.parents[j] >= 0 and sk.parents[j] not in driven]
        if gaps:
            raise SynthesisError(f"driven avatar joints below undriven ones: {gaps}")

    def joint_sources(self) -> list[tuple[int, ...]]:
        """Per avatar joint, the Kinect joint indices its rotation reads (empty: undriven)."""
        out: list[tuple[int, ...]] = [()] * self.target.n_joints
        triad = (self.mapping.root, *self.mapping.hips)
        out[self.target.index(PELVIS)] = tuple(self.kinect_index(n) for n in triad)
        torso = (self.mapping.root, self.mapping.neck)  # the torso scale reads them too
        for d in self.drives():
            names = dict.fromkeys((*d.kinect_joints, *(torso if d.torso else ())))
            out[self.target.index(d.joint)] = tuple(self.kinect_index(n) for n in names)
        return out

    def __call__(
        self, positions: np.ndarray, orientations: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """``root_pos (N, 3)`` and ``local_rot (N, J, 4)`` of the avatar for Kinect
        ``positions (N, K, 3)`` and world ``orientations (N, K, 4)`` (finite)."""
        sk = self.target
        n = positions.shape[0]
        world = np.tile(quat.IDENTITY, (n, sk.n_joints, 1))
        pos = np.zeros((n, sk.n_joints, 3))
        pos[:, 0] = positions[:, self.kinect_index(self.mapping.root)]
        drives = {sk.index(d.joint): d for d in self.drives()}
        pelvis = sk.index(PELVIS)
        driven = sorted({*drives, pelvis})
        local = np.tile(quat.IDENTITY, (n, sk.n_joints, 1))
        torso = self.torso_scaled(positions)
        # Undriven joints keep their rest local rotation, so only the driven ones (and their
        # ancestors, all driven or the root) need an absolute rotation and a position.
        for j in driven:
            parent = sk.parents[j]
            pos[:, j] = pos[:, parent] + rotate(world[:, parent], sk.offsets[j])
            if j == pelvis:
                world[:, j] = self._pelvis(positions)
            else:
                aims = torso if drives[j].torso else positions
                world[:, j] = self._bone(drives[j], world[:, parent], pos[:, j], aims, orientations)
            local[:, j] = quat.mul(quat.conj(world[:, parent]), world[:, j])
        return pos[:, 0], local

    def _pelvis(self, positions: np.ndarray) -> np.ndarray:
        """``(N, 4)``: the rotation taking the avatar's rest pelvis-to-hip vectors onto the
        Kinect's spine-base-to-hip vectors."""
        sk = self.target
        root = positions[:, self.kinect_index(self.mapping.root)]
        hips = [positions[:, self.kinect_index(h)] - root for h in self.mapping.hips]
        rest = [sk.offsets[sk.index(h)] for h in PELVIS_TRIAD]
        now = frame_from_pair(*hips)
        then = frame_from_pair(*rest)
        return quat.from_matrix(now @ then.T)

    def _bone(self, drive, parent_world, start, positions, orientations) -> np.ndarray:
        """``(N, 4)`` absolute rotation of one driven bone (module docstring) aiming at
        Kinect ``positions (N, K, 3)`` (torso-scaled for spine and neck bones)."""
        if self.roll == "sensor":
            sensor = orientations[:, self.kinect_index(drive.orient)]
            world = quat.mul(sensor, self.rest_alignment(drive))
        else:
            world = parent_world
        if drive.aim is None:
            return world
        bone = self.target.offsets[self.target.index(drive.child)]
        target = positions[:, self.kinect_index(drive.aim)] - start
        world = quat.mul(quat.shortest_arc(rotate(world, bone), target), world)
        if self.roll == "hinge" and drive.bend is not None:
            world = self._hinge_roll(
                drive, world, positions[:, self.kinect_index(drive.aim)], positions
            )
        return world

    def _hinge_roll(self, drive, world, end, positions) -> np.ndarray:
        """``world (N, 4)`` twisted about the bone so that its child's measured direction
        bends towards ``drive.bend`` (module docstring), faded in with the bend."""
        child = next(d for d in self.mapping.drives if d.joint == drive.child)
        axis = self.target.offsets[self.target.index(drive.child)]
        axis = axis / np.linalg.norm(axis)
        seen = rotate(quat.conj(world), positions[:, self.kinect_index(child.aim)] - end)
        seen_perp = seen - np.sum(seen * axis, -1, keepdims=True) * axis
        bend = np.asarray(drive.bend) - np.dot(drive.bend, axis) * axis
        angle = np.arctan2(quat.cross(bend, seen_perp) @ axis, seen_perp @ bend)
        sine = np.linalg.norm(seen_perp, axis=-1) / np.maximum(np.linalg.norm(seen, axis=-1), 1e-12)
        lo, hi = BEND_FADE
        weight = np.clip((sine - lo) / (hi - lo), 0.0, 1.0)
        return quat.mul(world, quat.from_axis_angle(axis, weight * angle))
