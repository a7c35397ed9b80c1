"""The corruption suite is flagged every time by the check for its defect, never the clean."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.sim import corrupt
from avatarsim.sim.plausibility import check_motion

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


def _rest_with_left_knee(body, flexion_deg: float, frames: int = 20) -> Motion:
    """The rest pose (standing, legs straight down, facing +X) with the left shank turned
    ``flexion_deg`` about the world's left-right axis (+Y) at the knee: positive swings the
    ankle backwards (flexion), negative forwards (hyperextension). In the rest pose every
    joint frame is the world frame, so this rotation is the knee's local rotation; nothing
    about the body's hinge axes or ranges is used."""
    sk = body.skeleton
    rot = np.zeros((frames, sk.n_joints, 4))
    rot[..., 0] = 1.0
    knee = body.anatomy.body17["l_knee"]
    rot[:, knee] = quat.from_scipy(Rotation.from_euler("y", flexion_deg, degrees=True))
    root = np.tile([0.0, 0.0, body.root_height], (frames, 1))
    return Motion(sk, 30.0, root, rot)


def _knee_angle_deg(motion: Motion) -> float:
    """Flexion measured on the positions: the angle between thigh (hip -> knee) and shank
    (knee -> ankle), signed + when the ankle is behind the thigh's line (-X), frame 0."""
    b17 = body17_positions(motion)[0]
    hip, knee, ankle = (
        b17[BODY17.index("l_hip")],
        b17[BODY17.index("l_knee")],
        b17[BODY17.index("l_ankle")],
    )
    thigh, shank = knee - hip, ankle - knee
    angle = np.degrees(np.arccos(thigh @ shank / np.linalg.norm(thigh) / np.linalg.norm(shank)))
    behind = np.cross(thigh, shank)[1] > 0  # thigh x shank along +Y: the ankle went back
    return float(angle if behind else -angle)


@pytest.mark.parametrize("flexion_deg", [170.0, -30.0], ids=["flexed_170", "hyperextended_30"])
def test_an_anatomically_impossible_knee_is_flagged(flexion_deg):
    """Anatomical facts, not the check's table: healthy adult knees flex to about 140
    degrees actively and 160 passively (heel against buttock), and extend to within a few
    degrees of straight (Soucie et al. 2011, Haemophilia 17(3):500-507, normal knee flexion
    ~140, extension ~0-5 degrees; hyperextension over 10-15 degrees is genu recurvatum, a
    pathology). A knee flexed 170 degrees or hyperextended 30 must be flagged; the straight
    standing knee must not."""
    body = build_body(generate("walk", duration_s=0.1).skeleton)
    straight = _rest_with_left_knee(body, 0.0)
    assert abs(_knee_angle_deg(straight)) < 1.0
    assert not check_motion(straight, body).flagged("joint_limits")
    bent = _rest_with_left_knee(body, flexion_deg)
    assert _knee_angle_deg(bent) == pytest.approx(flexion_deg, abs=1.0)  # as built
    report = check_motion(bent, body)
    assert report.flagged("joint_limits")
    assert report.values["joint_limit_violation_frac"] == 1.0
    knee = body.skeleton.names[body.anatomy.body17["l_knee"]]
    violations = report.contract()["details"]["joint_limits"]["violations"]
    assert any(name.startswith(knee) for name in violations), violations


def test_corrupt_names_each_defect_by_its_check():
    motion = generate("walk", duration_s=0.5, seed=1)
    body = build_body(motion.skeleton)
    stance = np.zeros(motion.n_frames, bool)
    raised = corrupt.corrupt("floating", motion, body, stance, np.random.default_rng(0))
    np.testing.assert_allclose(raised.root_pos[:, 2] - motion.root_pos[:, 2], 0.15)
    assert set(corrupt.DEFECTS) == set(DEFECTS)
    with pytest.raises(ValueError, match="defects"):
        corrupt.corrupt("melting", motion, body, stance, np.random.default_rng(0))
