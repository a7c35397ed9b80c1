"""Trials: built-in takes differ as repeated mocap trials do; turning moves only the test motion."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.synthesis.evaluate import Trial, builtin_trials, turned


def test_builtin_takes_differ_in_tempo_and_amplitude():
    trials = builtin_trials(("box",), n_subjects=1, n_takes=2, duration_s=0.5, seed=4)
    subjects = [t.motion.meta["subject"] for t in trials]
    for key in ("tempo", "amplitude"):
        ratio = subjects[0][key] / subjects[1][key]
        assert ratio != pytest.approx(1.0, abs=1e-3) and 0.7 < ratio < 1.4
    assert subjects[0]["height_m"] == subjects[1]["height_m"]


def test_heading_turns_only_the_test_motion():
    motion = generate("box", Subject(), 0.5, 90.0, seed=1)
    trial = Trial(motion, "box", "a", 1, "box_a_1", 5)
    same = turned(trial, 0.0)
    assert same is motion
    out = turned(trial, 90.0)
    yaw = np.arctan2(out.root_pos[0, 1], out.root_pos[0, 0]) - np.arctan2(
        motion.root_pos[0, 1], motion.root_pos[0, 0]
    )
    assert 0 < abs(np.degrees(np.angle(np.exp(1j * yaw)))) <= 90.0
    np.testing.assert_allclose(out.root_pos[:, 2], motion.root_pos[:, 2])
