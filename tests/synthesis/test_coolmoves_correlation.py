"""The hand-foot correlation filter reproduces the paper's observations (CoolMoves §3.1.2):
hand-dominant activities (basketball, climbing) above 0.5 on average, swimming below 0.2,
and nearly 60% of swimming removed at the threshold of 0.1; measured on CMU, the paper's
source (tests/measurements/hand_foot_correlation.py prints the whole table)."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.synthesis.coolmoves.correlation import hand_foot_correlation, keeps
from avatarsim.synthesis.coolmoves.database import hands_and_feet
from tests.conftest import require
from tests.measurements.hand_foot_correlation import cmu_scores


@pytest.mark.mocap
def test_papers_observations_on_cmu(mocap_dir):
    require((mocap_dir / "cmu").is_dir(), f"no CMU clips in {mocap_dir / 'cmu'}")
    scores = {k: np.asarray(v) for k, v in cmu_scores(mocap_dir).items()}
    assert scores["basketball"].mean() > 0.5 and scores["climbing"].mean() > 0.5
    assert scores["swimming"].mean() < 0.2
    assert 0.4 <= np.mean(scores["swimming"] < 0.1) <= 0.8


def test_generated_swimming_is_filtered_and_hand_dominant_dribbling_kept():
    """The generator's front crawl (hands ahead, feet behind the head) scores below the
    paper's 0.2 and is removed; its dribbling scores above the paper's 0.5."""
    subject = Subject(height_m=1.75)
    swim = generate("swim", subject, 4.0, 90.0, seed=0)
    dribble = generate("dribble", subject, 4.0, 90.0, seed=0)
    assert hand_foot_correlation(*hands_and_feet(swim)) < 0.2
    assert not keeps(*hands_and_feet(swim))
    assert hand_foot_correlation(*hands_and_feet(dribble)) > 0.5
