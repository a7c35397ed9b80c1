"""A method scored end to end: its physics is checked with the caller's settings."""

from __future__ import annotations

import pytest

from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.render_cams import VRSetup
from avatarsim.scripts.method_score import score_method
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.sim.plausibility import check_humanoid
from avatarsim.sim.thresholds import CheckConfig
from tests.synthesis.conftest import TruthReplay


@pytest.fixture(scope="module")
def walk():
    motion = generate("walk", Subject(height_m=1.75), 1.5, 90.0, seed=2)
    return motion, VRSetup().sample(motion, seed=0)


def test_the_physics_of_the_output_uses_the_given_settings(walk):
    truth, stream = walk
    slippery = CheckConfig(friction=0.1)
    result = score_method(TruthReplay(truth), truth, stream, slippery)
    # The output is the truth: its physics is the truth's under the same settings...
    assert result.physics == pytest.approx(
        check_humanoid(humanoid_for(truth), slippery).values, rel=1e-5, abs=1e-9
    )
    assert result.score.err_cm["full"] == pytest.approx(0.0, abs=1e-9)
    # ...and the settings matter: on a slippery floor the walk needs forces from nowhere.
    default = score_method(TruthReplay(truth), truth, stream, CheckConfig())
    key = "residual_force_bw_p95"
    assert result.physics[key] > default.physics[key]
