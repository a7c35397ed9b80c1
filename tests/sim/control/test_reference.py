"""The reference: read at a fractional clock between its frames (held past the end), looped
on its gait cycle without a seam."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.sim.control.controller import Controller
from avatarsim.sim.control.model import control_model
from avatarsim.sim.control.reference import looped


@pytest.fixture(scope="module")
def body():
    return build_body(load_rig("avatar").skeleton)


@pytest.fixture(scope="module")
def walk_reference(body):
    walk = generate("walk", duration_s=1.0, fps=30.0)
    return Controller(control_model(body.spec)).reference(body.qpos_from_motion(walk), walk.fps)


def test_reference_at_a_frame_is_that_frame(walk_reference):
    ref = walk_reference
    for frame in (0, 7, ref.n_frames - 1):
        point = ref.at(float(frame))
        np.testing.assert_allclose(point.qpos, ref.qpos[frame], atol=1e-12)
        np.testing.assert_array_equal(ref.frame_qpos(point.frame), ref.qpos[frame])
        np.testing.assert_allclose(ref.sites_at(float(frame)), ref.sites[frame], atol=1e-12)
        np.testing.assert_allclose(point.com, ref.com[frame], atol=1e-12)


def test_reference_between_frames_is_linear_and_held_past_the_end(walk_reference):
    """Halfway between frames 4 and 5: the mean of their velocities and sites; hinge angles
    halfway too (the manifold only matters for the root's quaternion). Past the end: the
    last frame."""
    ref = walk_reference
    point = ref.at(4.5)
    np.testing.assert_allclose(point.qvel, (ref.qvel[4] + ref.qvel[5]) / 2, atol=1e-12)
    np.testing.assert_allclose(ref.sites_at(4.5), (ref.sites[4] + ref.sites[5]) / 2, atol=1e-12)
    np.testing.assert_allclose(point.qpos[7:], (ref.qpos[4, 7:] + ref.qpos[5, 7:]) / 2, atol=1e-9)
    np.testing.assert_array_equal(ref.frame_qpos(4.5), ref.qpos[4])  # 4.5 rounds to even
    assert mujoco.mju_norm(point.qpos[3:7]) == pytest.approx(1.0)
    last = ref.at(ref.n_frames + 3.0)
    assert last.frame == ref.n_frames - 1
    np.testing.assert_allclose(ref.sites_at(ref.n_frames + 3.0), ref.sites[-1], atol=1e-12)
    clocks = np.array([0.0, 4.5, ref.n_frames - 1.0])
    np.testing.assert_array_equal(ref.sites_at(clocks)[1], ref.sites_at(4.5))


def test_clip_too_short_to_loop_is_refused(body):
    model = control_model(body.spec)
    with pytest.raises(MotionValueError, match="too short to loop"):
        looped(np.tile(model.qpos0, (2, 1)), 30.0, 5.0)


def test_looped_clip_continues_the_walk(body):
    """A 2 s walk looped to 5 s keeps moving forward at the clip's speed, without jumps."""
    walk = generate("walk", duration_s=2.0, fps=30.0)
    qpos = body.qpos_from_motion(walk)
    out = looped(qpos, walk.fps, 5.0)
    assert out.shape == (151, qpos.shape[1])
    np.testing.assert_array_equal(out[:24], qpos[:24])  # the clip plays first (cycle >= 0.8 s)
    step = np.linalg.norm(np.diff(out[:, :2], axis=0), axis=1)
    speed = np.linalg.norm(np.diff(qpos[:, :2], axis=0), axis=1)
    assert step.max() < 2.0 * speed.max()  # no seam jump
    assert out[-1, 0] > 2.3 * qpos[-1, 0]  # 5 s of walking go 2.5x as far as 2 s
