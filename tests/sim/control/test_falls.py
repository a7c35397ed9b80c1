"""Fall criteria: a low head, a tilted root, a lost body or a diverged simulation is a fall;
a body left behind by its reference is lost."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.sim.control.controller import control
from avatarsim.sim.control.falls import HEAD, fallen, first_fall, tilt_deg
from avatarsim.sim.control.model import control_model
from avatarsim.sim.control.settings import ControlSettings

UPRIGHT = np.array([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0])


def _frames(n: int = 5):
    """``n`` upright frames with the head at 1.6 m, the same for the reference."""
    qpos = np.tile(UPRIGHT, (n, 1))
    sites = np.zeros((n, 17, 3))
    sites[:, HEAD, 2] = 1.6
    return qpos, qpos.copy(), sites, sites.copy(), np.zeros(n, bool)


def test_each_criterion_alone_is_a_fall():
    settings = ControlSettings()
    qpos, qpos_ref, sites, ref_sites, unstable = _frames()
    assert not fallen(settings, qpos, qpos_ref, sites, ref_sites, unstable).any()
    sites[1, HEAD, 2] = 0.5 * 1.6  # head below 0.6 of the reference's
    lying = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])  # 90 degrees about X
    qpos[2, 3:7] = lying
    sites[3] += [0.6, 0.0, 0.0]  # everything 0.6 m away: lost
    unstable[4] = True
    frames = fallen(settings, qpos, qpos_ref, sites, ref_sites, unstable)
    assert frames.tolist() == [False, True, True, True, True]
    np.testing.assert_allclose(tilt_deg(qpos[2:3], qpos_ref[2:3]), [90.0])
    assert first_fall(frames) == 1 and first_fall(np.zeros(3, bool)) is None


def test_a_body_left_behind_by_its_reference_is_lost():
    """The reference stands, then jumps 1 m sideways: the humanoid stays up but is lost
    (mean body17 distance over 0.5 m) from the jump on."""
    model = control_model(build_body(load_rig("avatar").skeleton).spec)
    jumped = np.tile(model.qpos0, (31, 1))
    jumped[15:, 1] += 1.0
    result = control(model, jumped, 30.0)
    assert result.fall_frame == 15
    assert result.body17_error[:15].mean() < 0.01
