"""Beyond the paper: two-bone arm IK toward the controllers and the foot-contact clean-up."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.motion import forward_kinematics
from avatarsim.avatar_models.rigs import identify_rig, load_rig
from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.base import TrackingFrame
from avatarsim.synthesis.coolmoves import CoolMoves, Options, build_database
from avatarsim.synthesis.coolmoves.accuracy import stance_skating_cm_s
from avatarsim.synthesis.coolmoves.database import driver_positions
from avatarsim.synthesis.scoring import body17_errors_cm, hand_correlation
from avatarsim.synthesis.two_bone import chain_fk, solve
from tests.synthesis.conftest import TEST_SUBJECT


@pytest.fixture(scope="module")
def stream(test_motion):
    return VRSetup().sample(test_motion, seed=0)


def _arm(sk):
    rig = identify_rig(sk)
    joints = tuple(sk.index(rig.body17[f"l_{p}"]) for p in ("shoulder", "elbow", "wrist"))
    return joints, sk.chain(joints[-1])


def test_chain_fk_is_the_rigs_forward_kinematics():
    sk = load_rig("avatar").skeleton
    rig = identify_rig(sk)
    rng = np.random.default_rng(2)
    rot = quat.from_scipy(Rotation.random(2 * sk.n_joints, random_state=3)).reshape(2, -1, 4)
    root, scale = rng.normal(size=(2, 3)), np.array([0.9, 1.2])
    chains = np.array([sk.chain(sk.index(rig.body17[f"{s}_wrist"])) for s in "lr"])
    for b in range(2):
        pos, glob = forward_kinematics(
            sk.scaled(scale[b]), root[b : b + 1], quat.to_matrix(rot[b : b + 1])
        )
        globs, positions = chain_fk(rot, root, sk.offsets, scale, chains[0])
        np.testing.assert_allclose(positions[b], pos[0, chains[0]], atol=1e-12)
        np.testing.assert_allclose(globs[b], glob[0, chains[0]], atol=1e-12)
        # Both arms in one pass: each the same as on its own.
        globs, positions = chain_fk(rot, root, sk.offsets, scale, chains)
        np.testing.assert_allclose(positions[b], pos[0, chains], atol=1e-12)
        np.testing.assert_allclose(globs[b], glob[0, chains], atol=1e-12)


@pytest.mark.parametrize("reach", [0.8, 1.5])
def test_two_bone_reaches_a_target_and_keeps_the_hand(reach):
    sk = load_rig("avatar").skeleton
    (i, j, k), chain = _arm(sk)
    rot = np.tile(quat.IDENTITY, (1, sk.n_joints, 1))
    rot[0, j] = quat.from_axis_angle(np.array([0.0, 0, 1]), np.array(0.6))  # a bent elbow
    root, scale = np.zeros((1, 3)), np.ones(1)
    globs, pos = chain_fk(rot, root, sk.offsets, scale, chain)
    upper, lower = (np.linalg.norm(sk.offsets[n]) for n in (j, k))
    # A target in front of the shoulder at ``reach`` times the arm's length.
    target = pos[:, -3] + reach * (upper + lower) * np.array([[0.6, 0.0, -0.8]])
    out = solve(rot, globs[:, -4:], pos[:, -4:], (i, j, k), target)
    new_globs, new_pos = chain_fk(out, root, sk.offsets, scale, chain)
    np.testing.assert_allclose(new_pos[:, -3], pos[:, -3], atol=1e-12)  # shoulder stays
    np.testing.assert_allclose(new_globs[:, -1], globs[:, -1], atol=1e-9)  # hand keeps its turn
    if reach < 1:
        np.testing.assert_allclose(new_pos[:, -1], target, atol=1e-9)
    else:  # out of reach: a straight arm pointing at the target
        direction = (target - new_pos[:, -3]) / np.linalg.norm(target - new_pos[:, -3])
        got = new_pos[:, -1] - new_pos[:, -3]
        np.testing.assert_allclose(got, (upper + lower) * direction, atol=1e-6)
    # The elbow only bends about its hinge: its rotation axis stays the bend-plane normal.
    axis = quat.mul(quat.conj(rot[0, j]), out[0, j])[1:]
    assert abs(axis[0]) + abs(axis[1]) < 1e-9 * max(np.linalg.norm(axis), 1.0)


def test_arm_ik_brings_the_hands_to_the_controllers(small_db, test_motion, stream):
    paper = CoolMoves(small_db, TEST_SUBJECT.height_m, Options(arm_ik=0.0)).run(stream)
    fixed = CoolMoves(small_db, TEST_SUBJECT.height_m, Options(arm_ik=1.0)).run(stream)
    _, sides = driver_positions(fixed, small_db.drivers)
    gap = np.linalg.norm(sides - stream.positions[:, 1:], axis=-1)[9:]
    assert np.percentile(gap, 90) < 0.01  # the joint limits may turn the hand a little
    err_paper = body17_errors_cm(paper, test_motion)
    err_fixed = body17_errors_cm(fixed, test_motion)
    assert err_fixed["hands"] < 0.5 * err_paper["hands"]
    assert err_fixed["full"] < err_paper["full"]
    assert min(hand_correlation(fixed, stream).values()) > 0.95


def test_streaming_equals_batch_with_corrections(small_db, stream):
    synth = CoolMoves(small_db, TEST_SUBJECT.height_m, Options(arm_ik=0.7, foot_contact=True))
    batch = synth.run(stream)
    synth.reset()
    poses = [synth.step(TrackingFrame.from_stream(stream, i)) for i in range(stream.n_samples)]
    np.testing.assert_allclose(np.stack([p.local_rot for p in poses]), batch.local_rot, atol=1e-12)
    np.testing.assert_allclose(np.stack([p.root_pos for p in poses]), batch.root_pos, atol=1e-12)


def test_foot_contact_cleanup_stops_skating(train_motions):
    runs = [m for m in train_motions if m.meta["activity"] == "run"]
    truth = generate("run", TEST_SUBJECT, 4.0, 90.0, seed=3)
    run_stream = VRSetup().sample(truth, seed=1)
    db = build_database(runs)
    results = {}
    for clean in (False, True):
        synth = CoolMoves(db, TEST_SUBJECT.height_m, Options(foot_contact=clean))
        out = synth.run(run_stream)
        skate = stance_skating_cm_s(out, synth.standing_ankle_height)
        results[clean] = (skate, body17_errors_cm(out, truth)["full"])
    (skate_raw, err_raw), (skate_clean, err_clean) = results[False], results[True]
    assert skate_raw > 20.0  # the paper's foot sliding is there to remove
    assert skate_clean <= 0.2 * skate_raw
    assert err_clean <= err_raw + 0.5
