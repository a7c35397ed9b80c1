"""The simulated study: exact offsets beat the fixed baseline on the bent-leg artefact and on
the tracked end effectors for every sampled user whose avatar's legs differ (issue 13)."""

from __future__ import annotations

import numpy as np
import pytest

from avatar_models.generator import generate, sample_subject
from render_cams.vr.noise import Drift, Latency, PositionJitter, RotationJitter
from synthesis.avatargo.study import LIMB_SPREAD, STRAP_MAX_M, sample_user, study_run

# The realistic VR noise of the scenarios (scripts/stages/devices.py REALISTIC_NOISE).
NOISE = (Latency(seconds=1 / 90), PositionJitter(), RotationJitter(), Drift())


@pytest.mark.parametrize("seed", range(4))
def test_exact_beats_fixed_on_bent_legs(seed):
    """Measured on seeds 0-7 (1 s of waving, noise on, the analytic solver): exact knee
    error 0.37-0.87 deg vs fixed 20.3-29.6 deg; exact end effectors 0.13-0.32 cm (worst
    joint's mean; the head by forward kinematics of eq. 4's bend, not a goal) vs fixed
    11.8-29.6 cm. Bounds: exact knees under 3 deg and below fixed, exact effectors under
    1 cm, fixed over 5 cm. Where the avatar's arm is shorter than the reach asks, the
    controller is attached to the hand (§3.4): 0-50 % of frames."""
    truth = generate("wave", sample_subject(np.random.default_rng(seed)), 1.0, 90.0, seed)
    user = sample_user(seed, truth.skeleton)
    assert abs(user.leg_scale - 1.0) <= LIMB_SPREAD
    assert all(np.linalg.norm(a.position) < 0.2 + STRAP_MAX_M for a in user.straps.values())
    result = study_run(truth, user, NOISE, fingers=False)
    exact, fixed = result["exact"], result["fixed"]
    assert exact["standing_frames"] > 0
    assert exact["knee_err_deg"] < 3.0
    if abs(user.leg_scale - 1.0) > 0.01:
        assert exact["knee_err_deg"] < fixed["knee_err_deg"]
    assert max(exact["effector_err_cm"].values()) < 1.0
    assert max(fixed["effector_err_cm"].values()) > 5.0
