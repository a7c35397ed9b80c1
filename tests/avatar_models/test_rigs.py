"""Rig files: every rig loads, body17 maps and left/right pairs are sound, identify_rig works."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.errors import RigError
from avatarsim.avatar_models.rigs import available_rigs, identify_rig, load_rig
from avatarsim.avatar_models.skeleton import Skeleton

RIGS = available_rigs()
# bandai.toml documents a rest pose that is not upright (bones along local X; the motion stands
# the body up), so rest-pose geometry is checked on the others only.
UPRIGHT_RIGS = [r for r in RIGS if r != "bandai"]
SIDES = [(b, "r_" + b[2:]) for b in BODY17 if b.startswith("l_")]


def test_kinect_rigs_are_installed():
    assert {"kinect_v2", "azure_kinect", "body17"} <= set(RIGS)


@pytest.mark.parametrize("name", RIGS)
def test_rig_loads_with_body17_map(name):
    rig = load_rig(name)
    assert rig.name == name
    assert set(rig.body17) == set(BODY17)
    idx = rig.body17_indices()
    assert len(set(idx.tolist())) == 17  # 17 distinct joints
    assert np.all(np.isfinite(rig.skeleton.offsets))


@pytest.mark.parametrize("name", RIGS)
def test_rig_left_right_pairs(name):
    """body17's left joints mirror onto the right ones; mirror_map is an involution."""
    sk = load_rig(name).skeleton
    m = sk.mirror_map()
    np.testing.assert_array_equal(m[m], np.arange(sk.n_joints))
    body17 = load_rig(name).body17
    for left, right in SIDES:
        assert m[sk.index(body17[left])] == sk.index(body17[right]), (left, right)


@pytest.mark.parametrize("name", UPRIGHT_RIGS)
def test_rig_rest_pose_upright_left_is_y(name):
    """Z up: head above pelvis above ankles; left of the body is +Y."""
    rig = load_rig(name)
    pos = rig.skeleton.rest_positions()[rig.body17_indices()]
    z = dict(zip(BODY17, pos[:, 2], strict=True))
    assert z["head"] > z["pelvis"] > z["l_knee"] > z["l_ankle"]
    y = dict(zip(BODY17, pos[:, 1], strict=True))
    assert y["l_shoulder"] > y["r_shoulder"] and y["l_hip"] > y["r_hip"]


@pytest.mark.parametrize("name", RIGS)
def test_identify_rig_finds_itself(name):
    rig = load_rig(name)
    assert identify_rig(rig.skeleton).name == name
    renamed = Skeleton(rig.skeleton.names, rig.skeleton.parents, rig.skeleton.offsets)
    assert identify_rig(renamed).name == name  # by joint names alone


@pytest.mark.parametrize(
    ("name", "joints", "pairs"), [("kinect_v2", 25, 10), ("azure_kinect", 32, 13)]
)
def test_kinect_rigs_are_symmetric_adults(name, joints, pairs):
    sk = load_rig(name).skeleton
    assert sk.n_joints == joints
    m = sk.mirror_map()
    assert np.sum(m != np.arange(joints)) == 2 * pairs
    rest = sk.rest_positions() + sk.offsets[0]  # the root offset is its height above the floor
    np.testing.assert_allclose(rest[m] * [1, -1, 1], rest, atol=1e-12)  # exact mirror images
    head = rest[sk.index("Head" if name == "kinect_v2" else "HEAD"), 2]
    assert 1.55 < head < 1.70  # head centre of a 1.75 m adult
    assert 0.0 < rest[:, 2].min() < 0.1  # feet just above the floor
    body17 = load_rig(name).body17
    assert rest[sk.index(body17["l_foot"]), 0] > rest[sk.index(body17["l_ankle"]), 0] + 0.1


def test_kinect_v2_names_follow_the_sdk():
    rig = load_rig("kinect_v2")
    sk = rig.skeleton
    assert sk.names[0] == "SpineBase"
    parent = {n: (sk.names[p] if p >= 0 else "") for n, p in zip(sk.names, sk.parents, strict=True)}
    assert parent["Neck"] == "SpineShoulder" and parent["SpineShoulder"] == "SpineMid"
    assert parent["HandTipLeft"] == "HandLeft" and parent["ThumbLeft"] == "WristLeft"
    assert parent["ShoulderRight"] == "SpineShoulder" and parent["HipRight"] == "SpineBase"


def test_azure_kinect_names_follow_the_sdk():
    sk = load_rig("azure_kinect").skeleton
    k4abt = ["PELVIS", "SPINE_NAVAL", "SPINE_CHEST", "NECK", "CLAVICLE_LEFT", "SHOULDER_LEFT"]
    assert list(sk.names[:6]) == k4abt and sk.names[-1] == "EAR_RIGHT"
    assert sk.names[sk.parents[sk.index("NOSE")]] == "HEAD"
    assert sk.names[sk.parents[sk.index("CLAVICLE_RIGHT")]] == "SPINE_CHEST"


def test_identify_rig_rejects_unknown_names():
    sk = Skeleton(("a", "b", "c"), [-1, 0, 1], np.zeros((3, 3)))
    with pytest.raises(RigError, match="no known rig"):
        identify_rig(sk)
