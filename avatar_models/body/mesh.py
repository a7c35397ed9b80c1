"""Render mesh of the body: the same primitives as the MJCF, posed by global joint transforms.

The primitives are tessellated once in their body frames (:func:`mesh_template`); posing a
frame is one batched rigid transform of all vertices, so rendering many frames stays cheap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body.errors import BodyError
from avatarsim.avatar_models.body.geometry import Segment
from avatarsim.avatar_models.motion import Motion

CAPSULE_COUNT = (16, 16)
SPHERE_SUBDIVISIONS = 2


@dataclass(frozen=True)
class MeshTemplate:
    """Tessellated primitives in body frames.

    Attributes:
        vertices: ``(V, 3)`` in the frame of each vertex's body.
        vertex_body: ``(V,)`` skeleton joint index of each vertex's body.
        faces: ``(F, 3)`` vertex indices.
    """

    vertices: np.ndarray
    vertex_body: np.ndarray
    faces: np.ndarray


def _primitive(segment: Segment) -> trimesh.Trimesh:
    """One segment as a watertight mesh in its body frame."""
    if segment.shape == "box":
        transform = np.eye(4)
        transform[:3, :3] = segment.box_rotation
        transform[:3, 3] = segment.start
        return trimesh.creation.box(extents=2.0 * segment.half_extents, transform=transform)
    axis = segment.end - segment.start
    length = float(np.linalg.norm(axis))
    if segment.shape == "sphere" or length < 1e-9:
        mesh = trimesh.creation.icosphere(subdivisions=SPHERE_SUBDIVISIONS, radius=segment.radius)
        mesh.apply_translation(segment.start)
        return mesh
    # trimesh builds capsules along +Z, centred on the origin.
    mesh = trimesh.creation.capsule(height=length, radius=segment.radius, count=CAPSULE_COUNT)
    transform = trimesh.geometry.align_vectors([0.0, 0.0, 1.0], axis / length)
    transform[:3, 3] = 0.5 * (segment.start + segment.end)
    mesh.apply_transform(transform)
    return mesh


def mesh_template(segments: tuple[Segment, ...]) -> MeshTemplate:
    """Tessellate every segment once."""
    pieces = [_primitive(s) for s in segments]
    sizes = np.array([len(p.vertices) for p in pieces])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    return MeshTemplate(
        vertices=np.concatenate([p.vertices for p in pieces]),
        vertex_body=np.repeat([s.body for s in segments], sizes),
        faces=np.concatenate([p.faces + o for p, o in zip(pieces, starts, strict=True)]),
    )


def posed_mesh(desc, pose, global_rot: np.ndarray | None = None, frame: int = 0) -> trimesh.Trimesh:
    """The body posed by global joint positions ``(J, 3)`` and rotations ``(J, 3, 3)`` or
    ``(J, 4)`` wxyz, or by frame ``frame`` of a :class:`Motion` given as ``pose``."""
    n = desc.skeleton.n_joints
    if isinstance(pose, Motion):
        positions, rotations = pose.fk()
        positions, rotations = positions[frame], rotations[frame]
    else:
        if global_rot is None:
            raise BodyError("to_trimesh needs global rotations with global positions")
        positions = np.asarray(pose, dtype=float)
        rotations = np.asarray(global_rot, dtype=float)
        if rotations.shape == (n, 4):
            rotations = quat.to_matrix(rotations)
    if positions.shape != (n, 3) or rotations.shape != (n, 3, 3):
        raise BodyError(
            f"pose must be ({n}, 3) positions and ({n}, 3, 3) rotations, "
            f"got {positions.shape} and {rotations.shape}"
        )
    t = desc.mesh_template
    world = np.einsum("vab,vb->va", rotations[t.vertex_body], t.vertices) + positions[t.vertex_body]
    return trimesh.Trimesh(vertices=world, faces=t.faces, process=False)
