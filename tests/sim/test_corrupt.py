"""The corruption suite is flagged every time by the check for its defect, never the clean."""

from __future__ import annotations

import numpy as np
import pytest

from avatar_models.body import build_body
from avatar_models.formats import load_motion
from avatar_models.generator import generate
from sim import corrupt
from sim.plausibility import check_motion

DEFECTS = ("penetration", "floating", "joint_limits", "skating", "jitter")


def corrupted(motion, body, clean_report):
    stance = clean_report.per_frame()["contact_left"] > 0
    return {
        "penetration": corrupt.sink_feet(motion, 0.10),
        "floating": corrupt.float_body(motion, 0.15),
        "joint_limits": corrupt.bend_knee(motion, body, 40.0),
        "skating": corrupt.inject_sliding(motion, stance, 0.20),
        "jitter": corrupt.add_jitter(motion, np.random.default_rng(0), 0.01),
    }


def assert_suite(motion):
    body = build_body(motion.skeleton)
    clean = check_motion(motion, body)
    for defect, bad in corrupted(motion, body, clean).items():
        assert not clean.flagged(defect), (defect, clean.thresholds)
        assert check_motion(bad, body).flagged(defect), defect


@pytest.mark.parametrize(
    "activity",
    [
        "walk",
        "run",
        "squat",
    ],
)
def test_generated_suite_is_flagged(activity):
    assert_suite(generate(activity, duration_s=2.0, seed=1))


@pytest.mark.mocap
@pytest.mark.parametrize("clip", ["09_01", "16_35", "35_17"])
def test_cmu_suite_is_flagged(mocap_dir, clip):
    assert_suite(load_motion(mocap_dir / "cmu" / f"{clip}.bvh")[1:])


def test_bend_knee_goes_past_the_limit():
    motion = generate("walk", duration_s=1.0)
    body = build_body(motion.skeleton)
    report = check_motion(corrupt.bend_knee(motion, body, 40.0), body)
    knee = body.skeleton.names[body.anatomy.body17["l_knee"]]
    worst = report.contract()["details"]["joint_limits"]["violations"][f"{knee}:ry"]
    np.testing.assert_allclose(worst["max_deg"], 40.0, atol=0.5)
