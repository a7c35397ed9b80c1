"""Clean motions pass the default thresholds: generated activities and real CMU mocap."""

from __future__ import annotations

import pytest

from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.sim.plausibility import check_motion

KINEMATIC = ("penetration", "floating", "skating", "joint_limits", "self_collision", "jitter")


@pytest.mark.parametrize(
    "activity",
    [
        "walk",
        "run",
        "squat",
        "wave",
        "balance",
    ],
)
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
    assert report.values["contact_frac"] > 0.25  # fast running: short stances, long flights


@pytest.mark.mocap
def test_non_upright_rig_is_retargeted_before_checking(mocap_dir):
    clip = next((mocap_dir / "bandai").rglob("*walk_normal_001.bvh"))
    motion = load_motion(clip)[:60]
    report = check_motion(motion)
    assert report.meta["retargeted"] and report.meta["retarget_residual_cm_mean"] < 2.0
    # A clean walk, retargeted: the feet stay on the floor.
    assert report.values["penetration_cm_p95"] < 5.0 and report.values["contact_frac"] > 0.5
