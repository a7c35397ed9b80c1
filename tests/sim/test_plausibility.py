"""Clean motions pass the default thresholds: generated activities and real CMU mocap."""

from __future__ import annotations

import pytest

from avatar_models.formats import load_motion
from avatar_models.generator import generate
from sim.plausibility import RetargetingNeeded, check_motion

KINEMATIC = ("penetration", "floating", "skating", "joint_limits", "self_collision", "jitter")


@pytest.mark.parametrize("activity", ["walk", "run", "squat", "wave", "balance"])
def test_generated_activities_pass_kinematic_checks(activity):
    report = check_motion(generate(activity, duration_s=2.0))
    assert not set(report.failed_checks) & set(KINEMATIC), report.thresholds


@pytest.mark.parametrize("activity", ["squat", "wave", "balance"])
def test_generated_activities_pass_residual_force(activity):
    assert check_motion(generate(activity, duration_s=2.0)).passed


@pytest.mark.mocap
@pytest.mark.parametrize("clip", ["09_01", "16_35", "35_17"])
def test_cmu_running_passes_every_check(mocap_dir, clip):
    motion = load_motion(mocap_dir / "cmu" / f"{clip}.bvh")[1:]  # frame 0 is the T-pose
    report = check_motion(motion)
    assert report.passed, report.thresholds
    assert report.values["contact_frac"] > 0.3  # running: feet touch in about half the frames


@pytest.mark.mocap
def test_non_upright_rig_asks_for_retargeting(mocap_dir):
    clip = next((mocap_dir / "bandai").rglob("*walk_normal_001.bvh"))
    with pytest.raises(RetargetingNeeded, match="retarget"):
        check_motion(load_motion(clip)[:10])
