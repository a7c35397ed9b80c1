"""The avatar rig (avatar_models/rigs/avatar.toml): bones, body17 map, symmetry, rest pose."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.rigs import load_rig

CENTRE = [
    "Bip01",
    "Bip01 Pelvis",
    "Bip01 Spine",
    "Bip01 Spine1",
    "Bip01 Spine2",
    "Bip01 Neck",
    "Bip01 Head",
]
PER_SIDE = ["Clavicle", "UpperArm", "Forearm", "Hand", "Thigh", "Calf", "Foot", "Toe0"] + [
    f"Finger{d}{seg}" for d in range(5) for seg in ("", "1", "2")
]
FACE = {"Bip01 Jaw", "Bip01 L Eyelid", "Bip01 R Eyelid"}


@pytest.fixture(scope="module")
def rig():
    return load_rig("avatar")


def _world_rest(skeleton) -> np.ndarray:
    return skeleton.rest_positions() + skeleton.offsets[0]


def test_53_body_bones_plus_face_bones(rig):
    sk = rig.skeleton
    bones = {n for n, site in zip(sk.names, sk.is_site, strict=True) if not site}
    expected_body = set(CENTRE) | {f"Bip01 {s} {b}" for s in "LR" for b in PER_SIDE}
    assert len(expected_body) == 53
    assert bones - FACE == expected_body
    assert FACE <= bones


def test_end_sites_are_leaves(rig):
    sk = rig.skeleton
    sites = np.flatnonzero(sk.is_site)
    assert {"Bip01 HeadNub", "Bip01 L Toe0Nub", "Bip01 R Finger2Nub", "Bip01 L Heel"} <= {
        sk.names[j] for j in sites
    }
    for j in sites:
        assert sk.children(j).size == 0


def test_body17_map_points_to_the_right_anatomy(rig):
    sk = rig.skeleton
    assert set(rig.body17) == set(BODY17)
    pos = _world_rest(sk)[rig.body17_indices()]
    p = dict(zip(BODY17, pos, strict=True))
    assert p["head"][2] > p["neck"][2] > p["pelvis"][2]
    for side, sign in (("l", 1), ("r", -1)):
        assert (
            sign * p[f"{side}_wrist"][1]
            > sign * p[f"{side}_elbow"][1]
            > sign * p[f"{side}_shoulder"][1]
            > 0
        )
        assert (
            p[f"{side}_hip"][2]
            > p[f"{side}_knee"][2]
            > p[f"{side}_ankle"][2]
            > p[f"{side}_foot"][2]
        )
        assert p[f"{side}_foot"][0] > p[f"{side}_ankle"][0]  # toes point forward (+X)


def test_mirror_map_pairs_every_left_with_its_right(rig):
    sk = rig.skeleton
    mirror = sk.mirror_map()
    pos = _world_rest(sk)
    for j, name in enumerate(sk.names):
        if " L " in name:
            assert sk.names[mirror[j]] == name.replace(" L ", " R ")
        elif " R " not in name:
            assert mirror[j] == j
        np.testing.assert_allclose(pos[mirror[j]], pos[j] * [1, -1, 1], atol=1e-9)


def test_rest_pose_is_a_175_m_adult_standing_on_the_floor(rig):
    sk = rig.skeleton
    pos = _world_rest(sk)
    assert pos[:, 2].min() == pytest.approx(0.0, abs=1e-9)
    assert pos[:, 2].max() - pos[:, 2].min() == pytest.approx(1.75, abs=0.01)
    for side in "LR":
        for sole in ("Heel", "Toe0Nub"):
            assert pos[sk.index(f"Bip01 {side} {sole}"), 2] == pytest.approx(0.0, abs=1e-9)
    # Drillis & Contini (1966) fractions of stature: thigh 0.245, shank 0.246, upper arm 0.186,
    # forearm 0.146, shoulder height 0.818.
    length = {
        b: np.linalg.norm(sk.offsets[sk.index(f"Bip01 L {b}")])
        for b in ("Calf", "Foot", "Forearm", "Hand")
    }
    assert length["Calf"] / 1.75 == pytest.approx(0.245, abs=0.005)
    assert length["Foot"] / 1.75 == pytest.approx(0.246, abs=0.005)
    assert length["Forearm"] / 1.75 == pytest.approx(0.186, abs=0.005)
    assert length["Hand"] / 1.75 == pytest.approx(0.146, abs=0.005)
    assert pos[sk.index("Bip01 L UpperArm"), 2] / 1.75 == pytest.approx(0.818, abs=0.005)


def test_joint_limits_are_anatomical_and_mirrored(rig):
    limits = rig.skeleton.limits
    for side in "LR":
        for joint in ("UpperArm", "Forearm", "Thigh", "Calf", "Foot"):
            assert f"Bip01 {side} {joint}" in limits
    for name, axes in limits.items():
        for lo, hi in axes.values():
            assert lo <= hi
        if " L " in name:
            right = limits[name.replace(" L ", " R ")]
            for ax, (lo, hi) in axes.items():
                expected = (-hi, -lo) if ax in ("rx", "rz") else (lo, hi)
                assert right[ax] == pytest.approx(expected)
    knee = limits["Bip01 L Calf"]["ry"]
    assert knee[0] == pytest.approx(0.0) and np.degrees(knee[1]) >= 130  # AAOS: 0-135 deg
    hip = limits["Bip01 L Thigh"]["ry"]
    assert np.degrees(hip[0]) <= -110  # hip flexion beyond 110 deg (AAOS 120)
