"""Balance: the reference clock follows the capture point, swinging feet are weighted from
lift-off, a step shift is bounded and along the error."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.sim.control.balance import clock_rate, reference_stance, step_shift, swing_weights
from avatarsim.sim.control.controller import control
from avatarsim.sim.control.model import control_model
from avatarsim.sim.control.settings import ControlSettings


@pytest.fixture(scope="module")
def body():
    return build_body(load_rig("avatar").skeleton)


def test_reference_clock_follows_the_capture_point(body):
    """A reference standing 5 cm ahead: the body leans after it, its capture point leads, so
    the adaptive clock plays the reference faster than real time; without clock feedback the
    reference plays at real time."""
    model = control_model(body.spec)
    ahead = np.tile(model.qpos0, (31, 1))
    ahead[1:, 0] += 0.05
    adaptive = control(model, ahead, 30.0).reference_frame
    fixed = control(control_model(body.spec), ahead, 30.0, ControlSettings(clock_gain=0.0))
    step = model.opt.timestep * 30.0  # frames are sampled at the first step past them
    np.testing.assert_allclose(fixed.reference_frame, np.arange(31), atol=step + 1e-9)
    assert np.all(np.diff(adaptive[:20]) > 1.0)
    assert adaptive[-1] == 30.0  # the reference ended early and holds its last frame


def test_swing_weight_ramps_from_lift_off():
    """Left ankle on the floor for 3 frames, then 10 cm up for 6 frames at 10 fps with a
    0.3 s ramp: weights 0, then 1/3, 2/3, 1, 1, 1, 1 (a third more per frame); the right
    foot stands throughout."""
    heights = np.zeros((9, 2))
    heights[3:, 0] = 0.1
    settings = ControlSettings(swing_ramp_s=0.3, stance_height=0.03)
    np.testing.assert_array_equal(reference_stance(heights, 0.03)[:, 1], True)
    weights = swing_weights(heights, 10.0, settings)
    np.testing.assert_allclose(weights[:, 0], [0, 0, 0, 1 / 3, 2 / 3, 1, 1, 1, 1])
    assert not weights[:, 1].any()


def test_step_shift_and_clock_rate_are_bounded():
    """A reference facing +Y: a capture point 0.5 m ahead of it moves the step 0.2 x 0.5 m
    along world +Y; 2 m ahead, the step is cut to the largest shift. 1 m ahead or behind,
    the clock runs at its fastest or slowest."""
    facing_y = np.array([0.0, 0.0, 1.0, np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])
    settings = ControlSettings(capture_gain=(0.2, 0.5), max_step_shift=0.25)
    shift = step_shift(facing_y, np.array([0.5, 0.0]), settings)
    np.testing.assert_allclose(shift, [0.0, 0.1], atol=1e-12)
    shift = step_shift(facing_y, np.array([2.0, 0.0]), settings)
    np.testing.assert_allclose(shift, [0.0, 0.25], atol=1e-12)
    assert clock_rate(np.array([1.0, 0.0]), settings) == 1.0 + settings.max_clock_change
    assert clock_rate(np.array([-1.0, 0.0]), settings) == 1.0 - settings.max_clock_change
