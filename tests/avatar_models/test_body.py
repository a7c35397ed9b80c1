"""Body description: which joints are simulated, masses, ranges, scaling, errors."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body import (
    BodyDescription,
    BodyError,
    RestPoseNotUprightError,
    build_body,
)
from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.avatar_models.skeleton import Skeleton

# de Leva (1996) Table 4, male, per body (limbs counted on both sides).
DE_LEVA = {
    "head": 0.0694,
    "pelvis": 0.1117,
    "torso": 0.1633 + 0.1596,
    "upper_arm": 2 * 0.0271,
    "forearm": 2 * 0.0162,
    "hand": 2 * 0.0061,
    "thigh": 2 * 0.1416,
    "shank": 2 * 0.0433,
    "foot": 2 * 0.0137,
}


@pytest.fixture(scope="module")
def avatar() -> BodyDescription:
    return build_body(load_rig("avatar").skeleton)


def test_avatar_simulates_body_joints_and_toes_and_fixes_fingers_jaw_eyelids(avatar):
    names = avatar.skeleton.names
    simulated = {names[j] for j in avatar.simulated_joints}
    expected = {"Bip01", "Bip01 Pelvis", "Bip01 Spine", "Bip01 Spine1", "Bip01 Spine2"}
    expected |= {"Bip01 Neck", "Bip01 Head"}
    for s in "LR":
        expected |= {f"Bip01 {s} {b}" for b in ("Clavicle", "UpperArm", "Forearm", "Hand")}
        expected |= {f"Bip01 {s} {b}" for b in ("Thigh", "Calf", "Foot", "Toe0")}
    assert simulated == expected
    fixed = {names[j] for j in avatar.fixed_joints}
    assert {"Bip01 Jaw", "Bip01 L Eyelid", "Bip01 L Toe0Nub", "Bip01 R Finger42"} <= fixed


def test_stature_of_rigs_is_their_documented_size(avatar):
    # avatar.toml: heels on the floor, head top (HeadNub) at 1.75 m.
    assert avatar.stature == pytest.approx(1.75, abs=1e-9)
    # body17.toml: "a 1.75 m adult" whose head joint is a leaf (skull from ANSUR ratios).
    assert build_body(load_rig("body17").skeleton).stature == pytest.approx(1.75, abs=0.03)


@pytest.mark.parametrize("mass", [50.0, 75.0, 110.0])
def test_total_and_segment_masses_follow_de_leva(mass):
    body = build_body(load_rig("avatar").skeleton, mass_kg=mass)
    assert sum(s.mass for s in body.segments) == pytest.approx(mass, rel=1e-9)
    got = body.segment_masses()
    assert set(got) == set(DE_LEVA)
    for kind, fraction in DE_LEVA.items():
        assert got[kind] == pytest.approx(fraction * mass, rel=1e-9), kind


def test_thigh_centre_of_mass_is_de_leva_fraction_from_hip(avatar):
    thigh = next(s for s in avatar.segments if s.name == "thigh:Bip01 L Calf")
    knee = avatar.skeleton.offsets[avatar.skeleton.index("Bip01 L Calf")]
    np.testing.assert_allclose(thigh.com, 0.4095 * knee, atol=1e-12)


def test_joint_ranges_are_anatomical_and_mirrored(avatar):
    sk = avatar.skeleton
    deg = {
        j: {a: np.degrees(r) for a, r in axes.items()} for j, axes in avatar.hinge_ranges.items()
    }
    l_knee, r_knee = deg[sk.index("Bip01 L Calf")], deg[sk.index("Bip01 R Calf")]
    np.testing.assert_allclose(l_knee["y"], (-10, 135))  # AAOS knee flexion 135
    np.testing.assert_allclose(r_knee["y"], l_knee["y"])
    l_hip, r_hip = deg[sk.index("Bip01 L Thigh")], deg[sk.index("Bip01 R Thigh")]
    np.testing.assert_allclose(l_hip["y"], (-120, 30))  # flexion 120, extension 30
    np.testing.assert_allclose(l_hip["x"], (-30, 45))  # adduction 30, abduction 45
    np.testing.assert_allclose(r_hip["x"], (-45, 30))
    # Thoracolumbar flexion 80 is the three spine joints' together (a chain), not divided:
    # each may take all of it, the chain check and the MJCF's tendon limit their total.
    spine = tuple(sk.index(n) for n in ("Bip01 Spine", "Bip01 Spine1", "Bip01 Spine2"))
    for j in spine:
        assert deg[j]["y"][1] == pytest.approx(80)
    neck = (sk.index("Bip01 Neck"), sk.index("Bip01 Head"))
    assert avatar.chains == (spine, neck)
    np.testing.assert_allclose(deg[neck[0]]["y"], (-45, 45))  # cervical flexion/extension
    for axes in avatar.hinge_ranges.values():
        for lo, hi in axes.values():
            assert lo <= 0.0 <= hi  # the rest pose is inside every range


@pytest.mark.parametrize("height", [1.6, 1.9])
def test_scaling_to_height_scales_lengths_keeps_mass(avatar, height):
    scaled = avatar.scaled(height_m=height)
    factor = height / avatar.stature
    assert scaled.stature == pytest.approx(height, rel=1e-9)
    np.testing.assert_allclose(scaled.skeleton.offsets, avatar.skeleton.offsets * factor)
    assert scaled.root_height == pytest.approx(avatar.root_height * factor, rel=1e-9)
    assert sum(s.mass for s in scaled.segments) == pytest.approx(75.0)
    heavier = avatar.scaled(height_m=height, mass_kg=90.0)
    assert sum(s.mass for s in heavier.segments) == pytest.approx(90.0)


def test_segment_scale_lengthens_only_that_segment(avatar):
    longer = avatar.scaled(segment_scale={"thigh": 1.1})
    sk = avatar.skeleton
    for name in ("Bip01 L Calf", "Bip01 R Calf"):
        j = sk.index(name)
        np.testing.assert_allclose(longer.skeleton.offsets[j], 1.1 * sk.offsets[j])
    shank = sk.index("Bip01 L Foot")
    np.testing.assert_allclose(longer.skeleton.offsets[shank], sk.offsets[shank])
    assert longer.stature == pytest.approx(avatar.stature + 0.1 * 0.428, abs=1e-9)


def test_bad_inputs_raise_body_error():
    sk = load_rig("avatar").skeleton
    for height in (0.0, -1.0, 3.5, float("nan")):
        with pytest.raises(BodyError, match="height"):
            build_body(sk, height_m=height)
    with pytest.raises(BodyError, match="mass"):
        build_body(sk, mass_kg=-5.0)
    with pytest.raises(BodyError, match="foot"):
        build_body(sk, foot="sphere")
    with pytest.raises(BodyError, match="segment"):
        build_body(sk, segment_scale={"tail": 1.2})
    unknown = Skeleton(("a", "b", "c"), [-1, 0, 1], np.ones((3, 3)))
    with pytest.raises(BodyError, match="no known rig") as info:
        build_body(unknown)
    assert isinstance(info.value, AvatarsimError)


def test_a_rest_pose_that_does_not_stand_is_refused():
    # bandai.toml keeps the BVH's baked joint orientations: its rest pose is a crumpled heap.
    with pytest.raises(RestPoseNotUprightError, match="not upright"):
        build_body(load_rig("bandai").skeleton)


@pytest.mark.parametrize("side", "LR")
def test_foot_splits_at_the_ball_into_hindfoot_and_toe_boxes_on_one_sole(avatar, side):
    sk = avatar.skeleton
    ankle, toe = sk.index(f"Bip01 {side} Foot"), sk.index(f"Bip01 {side} Toe0")
    rest = sk.rest_positions()
    hind, toes = (
        next(s for s in avatar.segments if s.kind == "foot" and s.body == b) for b in (ankle, toe)
    )
    assert hind.shape == toes.shape == "box"

    def x_span(s):  # rest-pose world x of a box's back and front faces
        centre = s.start + rest[s.body]
        return centre[0] - s.half_extents[0], centre[0] + s.half_extents[0]

    # avatar.toml: heel joint 0.05 m behind the ankle, ball 0.144 m and toe tip 0.216 m in front;
    # the foot's ANSUR length (0.27 m of a 1.756 m man) reaches 3 mm beyond that tip.
    length = 0.270 / 1.756 * avatar.stature
    x_ankle = rest[ankle, 0]
    np.testing.assert_allclose(np.subtract(x_span(hind), x_ankle), (-0.05, 0.144), atol=1e-9)
    np.testing.assert_allclose(
        np.subtract(x_span(toes), x_ankle), (0.144, length - 0.05), atol=1e-9
    )
    # One sole, on the floor in the rest pose (heels and toe tips on the floor).
    soles = [s.lowest_z() + rest[s.body, 2] for s in (hind, toes)]
    np.testing.assert_allclose(soles, -avatar.root_height + rest[0, 2], atol=1e-9)
    # de Leva's foot mass split by length; the foot's CoM stays 44.15 % from the heel.
    foot_mass = 0.0137 * avatar.mass_kg
    assert toes.mass == pytest.approx(foot_mass * (length - 0.194) / length, rel=1e-9)
    assert hind.mass + toes.mass == pytest.approx(foot_mass, rel=1e-9)
    com = (hind.mass * (hind.com + rest[ankle]) + toes.mass * (toes.com + rest[toe])) / foot_mass
    assert com[0] - x_ankle == pytest.approx(-0.05 + 0.4415 * length, abs=1e-9)


def test_toe_hinges_have_aaos_mtp_ranges(avatar):
    for side in "LR":
        deg = {
            a: np.degrees(r)
            for a, r in avatar.hinge_ranges[avatar.skeleton.index(f"Bip01 {side} Toe0")].items()
        }
        np.testing.assert_allclose(deg["y"], (-70, 45))  # MTP extension 70, flexion 45
        for axis in "xz":
            assert np.ptp(deg[axis]) <= 10.0
