"""``BodyReplay``: a motion replayed on its humanoid, with the quantities several checks share.

Shapes: ``T`` frames, feet ordered (left, right), ``K`` foot primitives per side (a foot box,
and a toe box on rigs with simulated toes), sole points per primitive (heel, toe), sole
corners per primitive (heel-left, heel-right, toe-left, toe-right). Sole points lie on the
bottom face of each foot primitive (box or capsule) of :class:`avatar_models.body.Segment`,
moved with MuJoCo's body frames, so contacts follow the simulated geometry, not joints.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import mujoco
import numpy as np

from avatarsim.avatar_models.body import BodyDescription, Segment
from avatarsim.avatar_models.foot_contact import contact_mask, lasting
from avatarsim.sim.replay import ReplayTrace, replay_kinematic
from avatarsim.sim.thresholds import CheckConfig

SIDES = ("left", "right")


def _sole_points(seg: Segment) -> np.ndarray:
    """``(6, 3)`` heel, toe, then four sole corners of a foot primitive, in its body frame."""
    if seg.shape == "box":
        hx, hy, hz = seg.half_extents
        local = np.array(
            [
                [-hx, 0, -hz],
                [hx, 0, -hz],
                [-hx, hy, -hz],
                [-hx, -hy, -hz],
                [hx, hy, -hz],
                [hx, -hy, -hz],
            ]
        )
        return seg.start + local @ seg.box_rotation.T
    axis = seg.end - seg.start
    lateral = np.cross([0.0, 0.0, 1.0], axis)
    lateral *= seg.radius / max(np.linalg.norm(lateral), 1e-12)
    down = np.array([0.0, 0.0, -seg.radius])
    heel, toe = seg.start + down, seg.end + down
    return np.stack([heel, toe, heel + lateral, heel - lateral, toe + lateral, toe - lateral])


def finite_speed(x: np.ndarray, fps: float) -> np.ndarray:
    """``(T, ...)`` time derivative by central differences (one-sided at the ends)."""
    if x.shape[0] < 2:
        return np.zeros_like(x)
    return np.gradient(x, 1.0 / fps, axis=0)


@dataclass(frozen=True, eq=False)
class BodyReplay:
    """A motion's qpos replayed kinematically on the body's MuJoCo model.

    Attributes:
        body: the body description.
        model: its compiled MuJoCo model.
        qpos: ``(T, nq)``.
        fps: frames per second.
        trace: the MuJoCo replay (:class:`~sim.replay.ReplayTrace`).
        config: definitions and thresholds.
    """

    body: BodyDescription
    model: mujoco.MjModel
    qpos: np.ndarray
    fps: float
    trace: ReplayTrace
    config: CheckConfig

    @classmethod
    def run(
        cls,
        body: BodyDescription,
        model: mujoco.MjModel,
        qpos: np.ndarray,
        fps: float,
        config: CheckConfig,
    ) -> BodyReplay:
        return cls(body, model, qpos, fps, replay_kinematic(model, qpos), config)

    @property
    def n_frames(self) -> int:
        return self.qpos.shape[0]

    @cached_property
    def _feet(self) -> tuple[tuple[Segment, ...], tuple[Segment, ...]]:
        """Foot primitives per side (some rigs have a foot and a toe primitive per side)."""
        return tuple(
            tuple(s for s in self.body.segments if s.kind == "foot" and s.side == side)
            for side in SIDES
        )

    @cached_property
    def _sole_world(self) -> np.ndarray:
        """``(T, 2, K, 6, 3)`` heel, toe and corners of the ``K`` foot primitives per side."""
        names = self.body.skeleton.names
        local = np.stack([[_sole_points(s) for s in side] for side in self._feet])  # (2,K,6,3)
        ids = np.array([[self.model.body(names[s.body]).id for s in side] for side in self._feet])
        pos = self.trace.body_pos[:, ids]  # (T, 2, K, 3)
        rot = self.trace.body_rot[:, ids]  # (T, 2, K, 3, 3)
        return pos[:, :, :, None] + np.einsum("tfkij,fkpj->tfkpi", rot, local)

    @property
    def sole_points(self) -> np.ndarray:
        """``(T, 2, P, 3)`` heel and toe of each foot primitive (``P = 2K``) per side."""
        w = self._sole_world[:, :, :, :2]
        return w.reshape(w.shape[0], 2, -1, 3)

    @property
    def sole_corners(self) -> np.ndarray:
        """``(T, 2, 4K, 3)`` the corners of each side's sole primitives."""
        w = self._sole_world[:, :, :, 2:]
        return w.reshape(w.shape[0], 2, -1, 3)

    @cached_property
    def sole_velocity(self) -> np.ndarray:
        """``(T, 2, P, 3)`` velocity of the sole points (m/s)."""
        return finite_speed(self.sole_points, self.fps)

    @cached_property
    def point_contact(self) -> np.ndarray:
        """``(T, 2, P)`` sole points in contact: low, not moving vertically, slower than a
        swinging foot horizontally, for at least
        ``contact_min_s`` in a row (a swinging toe skimming the floor for a frame or two, as
        it does in normal gait with ~1-2 cm clearance, is no stance)."""
        c = self.config
        velocity = self.sole_velocity
        points = contact_mask(
            self.sole_points[..., 2],
            c.contact_height_m,
            vertical_velocity=velocity[..., 2],
            max_vertical_speed=c.contact_vz_m_s,
            horizontal_speed=np.linalg.norm(velocity[..., :2], axis=-1),
            max_horizontal_speed=c.contact_vxy_m_s,
        )
        run = max(1, int(np.ceil(c.contact_min_s * self.fps - 1e-9)))
        # A foot's contact (any of its points) must last ``run`` frames; its points keep
        # their own labels.
        return points & lasting(points.any(axis=2), run)[..., None]

    @property
    def foot_contact(self) -> np.ndarray:
        """``(T, 2)`` left/right foot in contact (heel or toe)."""
        return self.point_contact.any(axis=2)

    @cached_property
    def supported(self) -> np.ndarray:
        """``(T,)`` some body geom is within the contact height of the floor."""
        return self.trace.lowest_point < self.config.contact_height_m

    @cached_property
    def com(self) -> np.ndarray:
        """``(T, 3)`` whole-body centre of mass."""
        return self.trace.com(self.model)
