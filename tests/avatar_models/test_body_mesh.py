"""Render mesh of the body: the same primitives as the MJCF, posed per frame."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body import BodyError, build_body
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import load_rig


def _posed(rig: str, seed: int) -> Motion:
    sk = load_rig(rig).skeleton
    rng = np.random.default_rng(seed)
    rot = quat.from_axis_angle(
        rng.normal(size=(1, sk.n_joints, 3)), rng.uniform(-1, 1, (1, sk.n_joints))
    )
    return Motion(sk, 30.0, np.array([[0.3, -0.2, 1.1]]), rot)


def _distance_to_segments(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(P, S)`` distance of each point to each segment ``a[s] -> b[s]``."""
    ab = b - a
    t = np.einsum("psk,sk->ps", points[:, None] - a, ab) / np.maximum(np.sum(ab * ab, 1), 1e-18)
    closest = a + np.clip(t, 0.0, 1.0)[..., None] * ab
    return np.linalg.norm(points[:, None] - closest, axis=-1)


@pytest.mark.parametrize("rig", ["body17", "avatar", "cmu"])
def test_bone_capsules_lie_within_their_radius_of_the_posed_bones(rig):
    motion = _posed(rig, seed=3)
    body = build_body(motion.skeleton)
    sk = body.skeleton
    pos, rot = motion.fk()
    pos, rot = pos[0], rot[0]
    mesh = body.to_trimesh(pos, rot)
    pieces = mesh.split(only_watertight=False)
    assert len(pieces) == len(body.segments)
    assert all(p.is_watertight for p in pieces)
    # Every bone capsule lies on the surface at its radius around its bone, posed by forward
    # kinematics (the farthest vertex of a capsule from its axis is exactly at the radius).
    unmatched = list(range(len(pieces)))
    bones = [s for s in body.segments if s.shape == "capsule" and s.kind not in ("hand", "foot")]
    for segment in bones:
        child = sk.index(segment.name.split(":", 1)[1])
        a, b = pos[sk.parents[child]][None], pos[child][None]
        inside = [
            i
            for i in unmatched
            if abs(_distance_to_segments(pieces[i].vertices, a, b).max() - segment.radius) < 1e-9
        ]
        assert inside, segment.name
        unmatched.remove(inside[0])
    # What is left: two hands, two hindfeet, two toe boxes and the skull, a sphere around the
    # posed head.
    assert len(unmatched) == 7
    skull = next(s for s in body.segments if s.shape == "sphere")
    centre = rot[skull.body] @ skull.start + pos[skull.body]
    radii = [np.linalg.norm(pieces[i].vertices - centre, axis=1) for i in unmatched]
    assert sum(np.allclose(r, skull.radius, rtol=1e-6) for r in radii) == 1


def test_mesh_bounds_match_the_rest_pose_of_the_avatar():
    sk = load_rig("avatar").skeleton
    body = build_body(sk)
    rest = Motion(sk, 30.0, sk.offsets[:1], np.tile(quat.IDENTITY, (1, sk.n_joints, 1)))
    mesh = body.to_trimesh(rest)
    # avatar.toml: heels and toe tips on the floor, the head top (HeadNub) at 1.75 m.
    assert mesh.bounds[0, 2] == pytest.approx(0.0, abs=0.002)
    assert mesh.bounds[1, 2] == pytest.approx(1.75, abs=0.002)
    joints = rest.global_positions()[0]
    widest = max(s.radius for s in body.segments)
    assert np.all(mesh.bounds[0] >= joints.min(0) - widest)
    assert np.all(mesh.bounds[1] <= joints.max(0) + widest)
    # Arms span the T-pose: beyond the wrists, short of the finger tips.
    wrists = joints[[sk.index("Bip01 L Hand"), sk.index("Bip01 R Hand")], 1]
    assert mesh.bounds[1, 1] > wrists[0] and mesh.bounds[0, 1] < wrists[1]


def test_mesh_accepts_quaternions_and_rejects_bad_shapes():
    motion = _posed("body17", seed=1)
    body = build_body(motion.skeleton)
    from_motion = body.to_trimesh(motion, frame=0)
    from_quats = body.to_trimesh(motion.global_positions()[0], motion.global_rotations()[0])
    np.testing.assert_allclose(from_quats.vertices, from_motion.vertices, atol=1e-12)
    with pytest.raises(BodyError, match="pose"):
        body.to_trimesh(np.zeros((3, 3)), np.zeros((3, 3, 3)))
