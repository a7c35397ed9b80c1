"""Collision/render primitives of the body, in the frame of the body that carries them.

A body's frame is its joint's frame: at rest it is the world frame moved to the joint
(rest local rotations are the identity), so rest offsets give every point directly.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Segment:
    """One primitive with its share of the body's mass.

    Attributes:
        name: unique segment name (also the MuJoCo geom name).
        kind: de Leva segment kind (``"thigh"``, ``"torso"``...).
        side: ``"left"``, ``"right"`` or ``"center"``.
        body: index of the skeleton joint whose body carries it.
        shape: ``"capsule"``, ``"box"`` or ``"sphere"``.
        start, end: ``(3,)`` capsule axis end points in the body frame; the centre for
            spheres and boxes is ``start`` (= ``end``).
        radius: capsule/sphere radius (for a box, half its smallest extent).
        half_extents: ``(3,)`` box half sizes along its own axes (zeros otherwise).
        heading: box rotation about the body's Z axis (radians).
        mass: kg.
        com: ``(3,)`` centre of mass in the body frame.
    """

    name: str
    kind: str
    side: str
    body: int
    shape: str
    start: np.ndarray
    end: np.ndarray
    radius: float
    mass: float
    com: np.ndarray
    half_extents: np.ndarray = field(default_factory=lambda: np.zeros(3))
    heading: float = 0.0

    @property
    def box_rotation(self) -> np.ndarray:
        """``(3, 3)`` rotation of a box's own axes in the body frame (about Z by heading)."""
        c, s = np.cos(self.heading), np.sin(self.heading)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    def inertia(self) -> np.ndarray:
        """``(3, 3)`` inertia tensor about :attr:`com`, of a solid cylinder (capsules), box or
        sphere of this mass: the de Leva tables give masses and CoMs, shapes give the rest."""
        m = self.mass
        if self.shape == "sphere":
            return np.eye(3) * 0.4 * m * self.radius**2
        if self.shape == "box":
            a, b, c = 2.0 * self.half_extents
            local = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * m / 12.0
            rot = self.box_rotation
            return rot @ local @ rot.T
        axis = self.end - self.start
        length = float(np.linalg.norm(axis))
        d = axis / length
        along = 0.5 * m * self.radius**2
        across = m * (3.0 * self.radius**2 + length**2) / 12.0
        return across * (np.eye(3) - np.outer(d, d)) + along * np.outer(d, d)

    def volume(self) -> float:
        """m^3 of the primitive."""
        if self.shape == "box":
            return float(8.0 * np.prod(self.half_extents))
        ball = 4.0 / 3.0 * np.pi * self.radius**3
        return float(ball + np.pi * self.radius**2 * np.linalg.norm(self.end - self.start))

    def lowest_z(self) -> float:
        """Lowest point of the primitive along the body's Z axis (body frame)."""
        if self.shape == "box":
            corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
            pts = self.start + (corners * self.half_extents) @ self.box_rotation.T
            return float(pts[:, 2].min())
        return float(min(self.start[2], self.end[2]) - self.radius)


def combined_inertial(segments: list[Segment]) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, CoM ``(3,)`` and inertia ``(3, 3)`` about that CoM of segments on one body
    (parallel-axis theorem)."""
    mass = sum(s.mass for s in segments)
    com = sum(s.mass * s.com for s in segments) / mass
    inertia = np.zeros((3, 3))
    for s in segments:
        r = s.com - com
        inertia += s.inertia() + s.mass * (np.dot(r, r) * np.eye(3) - np.outer(r, r))
    return mass, com, inertia
