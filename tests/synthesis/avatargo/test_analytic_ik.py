"""The analytic per-tick IK (closed-form two-bone IK in place of the paper's Unity IK): checked
by the skeleton's own forward kinematics (:class:`~avatar_models.Motion`), not by the solver's."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import Motion, quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.generator.subject import Subject
from avatarsim.synthesis.avatargo.analytic_ik import LIMBS, AnalyticGoals, AnalyticIK
from avatarsim.synthesis.avatargo.spine import bend_angle, spine_bend_in_root
from avatarsim.synthesis.two_bone import unit

HEADING = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(0.6))


@pytest.fixture(scope="module")
def body():
    return build_body(generate("wave", Subject(), 0.1, 90.0, 0).skeleton)


def joint(body, name: str) -> int:
    return body.skeleton.index(body.rig.body17[name])


def solved(ik: AnalyticIK, body, goals: AnalyticGoals) -> tuple[np.ndarray, np.ndarray]:
    """World joint positions ``(B, J, 3)`` and rotations ``(B, J, 4)`` of the solution."""
    pose = ik.solve(*goals)
    motion = Motion(body.skeleton, 90.0, pose.root_pos, pose.local_rot)
    return motion.global_positions(), motion.global_rotations()


def standing_goals(body, end_pos: np.ndarray, bend: np.ndarray | None = None) -> AnalyticGoals:
    """Pelvis 1 m up facing ``HEADING``, feet and hands turned as the pelvis, ``end_pos``
    ``(B, 4, 3)`` for ankles and wrists."""
    b = end_pos.shape[0]
    pelvis = np.tile([0.2, -0.1, body.root_height], (b, 1))
    rot = np.tile(HEADING, (b, 1))
    bend = np.tile(quat.IDENTITY, (b, 1)) if bend is None else bend
    return AnalyticGoals(pelvis, rot, bend, rot, end_pos, np.tile(HEADING, (b, 4, 1)))


def test_limbs_reach_reachable_goals_exactly_with_the_goal_rotations(body):
    """Ankles and wrists land on goals within reach (knees and elbows bent), the pelvis on its
    goal, and the ankles and wrists take their goal rotations."""
    ik = AnalyticIK(body)
    rest = body.skeleton.rest_positions()
    pelvis = np.array([0.2, -0.1, body.root_height])
    # The rest T-pose placed on the pelvis goal, then each end pulled 12 cm towards its
    # upper joint and 5 cm forwards: inside every limb's reach, needing a bend.
    placed = pelvis + quat.rotate(HEADING, rest - rest[joint(body, "pelvis")])
    upper = placed[[joint(body, limb[0]) for limb in LIMBS]]
    end = placed[[joint(body, limb[2]) for limb in LIMBS]]
    toward = (upper - end) / np.linalg.norm(upper - end, axis=-1, keepdims=True)
    goal = end + 0.12 * toward + quat.rotate(HEADING, np.array([0.05, 0.0, 0.0]))
    pos, rot = solved(ik, body, standing_goals(body, goal[None]))
    ends = [joint(body, limb[2]) for limb in LIMBS]
    np.testing.assert_allclose(pos[0, ends], goal, atol=1e-9)
    np.testing.assert_allclose(pos[0, joint(body, "pelvis")], pelvis, atol=1e-12)
    np.testing.assert_allclose(np.abs(rot[0, ends] @ HEADING), 1.0, atol=1e-9)
    for limb in LIMBS:  # every limb bent to get there
        a, m, e = (pos[0, joint(body, n)] for n in limb)
        assert np.degrees(bend_angle(m - a, (e - m)[None]))[0] > 10.0


def test_limbs_stop_straight_towards_goals_beyond_reach(body):
    """A goal 1 m beyond each end: the limb straight (upper, middle and end joints on one
    line, as long as the two bones) and pointing at the goal."""
    ik = AnalyticIK(body)
    rest = body.skeleton.rest_positions()
    uppers = [joint(body, limb[0]) for limb in LIMBS]
    middles = [joint(body, limb[1]) for limb in LIMBS]
    ends = [joint(body, limb[2]) for limb in LIMBS]
    length = np.linalg.norm(rest[middles] - rest[uppers], axis=-1) + np.linalg.norm(
        rest[ends] - rest[middles], axis=-1
    )
    far = np.array([[0.3, 0.4, -1.5], [0.3, -0.4, -1.5], [1.0, 1.5, 1.0], [1.0, -1.5, -0.2]])
    goal = np.array([0.2, -0.1, body.root_height]) + quat.rotate(HEADING, far)
    pos, _ = solved(ik, body, standing_goals(body, goal[None]))
    upper, end = pos[0, uppers], pos[0, ends]
    np.testing.assert_allclose(np.linalg.norm(end - upper, axis=-1), length, atol=1e-9)
    along = (end - upper) / length[:, None]
    to_goal = (goal - upper) / np.linalg.norm(goal - upper, axis=-1, keepdims=True)
    np.testing.assert_allclose(along, to_goal, atol=1e-9)


def test_near_goals_stop_at_the_humanoids_flexion_limit(body):
    """An ankle goal at the hip: the knee flexes to the humanoid's knee range (135 deg in
    the avatar rig's MJCF, Bip01 L Calf:ry), no further."""
    ik = AnalyticIK(body)
    hip = np.array([0.2, -0.1, body.root_height]) + quat.rotate(
        HEADING, body.skeleton.rest_positions()[joint(body, "l_hip")]
    )
    goal = np.tile(hip + [0.0, 0.0, -0.05], (4, 1))
    pos, _ = solved(ik, body, standing_goals(body, goal[None]))
    a, k, e = (pos[0, joint(body, n)] for n in LIMBS[0])
    flexion = np.degrees(bend_angle(k - a, (e - k)[None]))[0]
    assert flexion == pytest.approx(135.0, abs=1e-6)


def test_spine_inclines_by_eq4s_angle(body):
    """The head moved 25 deg about the lateral axis around the root (root's rotation as at
    the walk-in): the avatar's upper body turns by eq. 4's alpha = 25 deg."""
    ik = AnalyticIK(body)
    rest = body.skeleton.rest_positions()
    pelvis, head, neck = (rest[joint(body, n)] for n in ("pelvis", "head", "neck"))
    w0 = quat.rotate(HEADING, head - pelvis)
    lateral = quat.rotate(HEADING, np.array([0.0, 1.0, 0.0]))
    w = quat.rotate(quat.from_axis_angle(lateral, np.array(np.radians(25.0))), w0)
    w0_in_root, _ = unit(quat.rotate(quat.conj(HEADING), w0))
    bend = spine_bend_in_root(w0_in_root, w[None], quat.unit_to_matrix(HEADING[None]))
    assert np.degrees(bend_angle(w0, w[None]))[0] == pytest.approx(25.0)
    ends = np.zeros((1, 4, 3))  # unreachable: only the spine matters here
    pos, _ = solved(ik, body, standing_goals(body, ends, bend))
    chest0 = quat.rotate(HEADING, neck - rest[ik.spine])
    chest = pos[0, joint(body, "neck")] - pos[0, ik.spine]
    assert np.degrees(bend_angle(chest0, chest[None]))[0] == pytest.approx(25.0, abs=1e-9)
    # A bend about the lateral axis: forwards, the chest stays in the sagittal plane.
    assert abs(chest @ lateral) == pytest.approx(abs(chest0 @ lateral), abs=1e-9)
