"""The AvatarGo synthesiser: registered under its names, needs the walk-in sample, streams
what it batches, holds lost devices without NaN, and rejects unknown offset kinds."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.generator.subject import Subject
from avatarsim.synthesis.avatargo import AvatarGo
from avatarsim.synthesis.avatargo.hands import REACH_SLACK_M
from avatarsim.synthesis.avatargo.study import sample_user, setup_for
from avatarsim.synthesis.avatargo.walk_in import walk_in
from avatarsim.synthesis.base import FrameBatch, SynthesisError, TrackingFrame, on_clock
from avatarsim.synthesis.methods import MethodInputs, build


@pytest.fixture(scope="module")
def session():
    truth = generate("wave", Subject(), 0.25, 90.0, 0)
    user = sample_user(5, truth.skeleton)
    setup = setup_for(user)
    sample = walk_in(setup, truth, user.seed, user.heading_rad)
    return truth, sample, setup.sample(truth, seed=user.seed)


def test_registered_and_needs_the_walk_in(session):
    truth, sample, stream = session
    inputs = MethodInputs(lambda: None, 1.75, truth.skeleton)
    with pytest.raises(SynthesisError, match=r"\[devices\] trackers = true"):
        build("avatargo", inputs)
    inputs.walk_in = sample
    for name, offsets in (("avatargo", "exact"), ("avatargo-fixed", "fixed")):
        synth = build(name, inputs)
        assert synth.name == name and synth.offsets == offsets
    with pytest.raises(SynthesisError, match="offsets must be"):
        AvatarGo(truth.skeleton, sample, offsets="magic")


def test_step_is_run_and_lost_devices_hold(session):
    truth, sample, stream = session
    synth = AvatarGo(truth.skeleton, sample)
    lost = stream.valid.copy()
    lost[10:20, 0] = False  # the headset drops out for 10 ticks
    stream = stream.replace(valid=lost, positions=np.where(lost[..., None], stream.positions, 0))
    batch = synth.run(stream)
    synth.reset()
    steps = [synth.step(TrackingFrame.from_stream(stream, i)) for i in range(stream.n_samples)]
    np.testing.assert_allclose(np.stack([p.root_pos for p in steps]), batch.root_pos, atol=1e-9)
    np.testing.assert_allclose(np.stack([p.local_rot for p in steps]), batch.local_rot, atol=1e-9)
    assert np.isfinite(batch.local_rot).all() and np.isfinite(batch.root_pos).all()


def test_a_lost_device_holds_its_last_pose(session):
    """While the headset is lost (ticks 10-19, its samples zeroed as a driver reports them),
    the avatar is the one of a stream whose headset stood still at its tick-9 pose: the
    last tracked pose is held, not replaced by any other."""
    truth, sample, stream = session
    hmd = list(stream.device_names).index("hmd")
    lost = stream.valid.copy()
    lost[10:20, hmd] = False
    zeroed = stream.replace(
        valid=lost,
        positions=np.where(lost[..., None], stream.positions, 0.0),
        quaternions=np.where(lost[..., None], stream.quaternions, quat.IDENTITY),
    )
    positions, quaternions = stream.positions.copy(), stream.quaternions.copy()
    positions[10:20, hmd], quaternions[10:20, hmd] = positions[9, hmd], quaternions[9, hmd]
    held = stream.replace(positions=positions, quaternions=quaternions)
    synth = AvatarGo(truth.skeleton, sample)
    out_lost, out_held = synth.run(zeroed), synth.run(held)
    np.testing.assert_allclose(out_lost.root_pos, out_held.root_pos, atol=1e-9)
    np.testing.assert_allclose(out_lost.local_rot, out_held.local_rot, atol=1e-9)


def test_unknown_solver_is_refused(session):
    truth, sample, _ = session
    with pytest.raises(SynthesisError, match="solver must be one of"):
        AvatarGo(truth.skeleton, sample, solver="unity")


def test_analytic_palm_holds_the_controller_wherever_the_arm_reaches(session):
    """The analytic solver (the default): where the wrist's goal under the controller lies
    within the arm's length from the shoulder (the output's own forward kinematics), the
    palm sits on the controller; beyond it, the hand stops short by the excess and the frame
    is reported attached once past the reach slack."""
    truth, sample, stream = session
    synth = AvatarGo(truth.skeleton, sample)
    assert synth.solver == "analytic"
    out = synth.run(stream)
    clocked = on_clock(stream)
    index = synth.device_index(FrameBatch.of_stream(clocked))
    goals = synth.analytic_goals(
        clocked.positions[:, index], quat.normalize(clocked.quaternions[:, index])
    )
    sk, body17 = synth.body.skeleton, synth.body.rig.body17
    rest = sk.rest_positions()
    palm, attached = np.array(synth.palm_distance), np.array(synth.attached)
    reached = 0
    for k, side in enumerate("lr"):
        s, e, w = (sk.index(body17[f"{side}_{j}"]) for j in ("shoulder", "elbow", "wrist"))
        arm = np.linalg.norm(rest[e] - rest[s]) + np.linalg.norm(rest[w] - rest[e])
        beyond = np.linalg.norm(goals.end_pos[:, 2 + k] - out.global_positions()[:, s], axis=-1)
        beyond -= arm  # (T,) how far the wrist's goal lies past the straight arm
        inside = beyond < 0
        reached += inside.sum()
        np.testing.assert_allclose(palm[inside, k], 0.0, atol=1e-9)
        np.testing.assert_allclose(palm[~inside, k], beyond[~inside], atol=1e-9)
        np.testing.assert_array_equal(attached[:, k], beyond > REACH_SLACK_M)
    assert reached > 0
